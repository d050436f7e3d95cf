#include "support/level0_values.hpp"

#include <cstring>

#include "resoct/io/formats/pyramid_source.hpp"

namespace resoct {

std::vector<double> level0_values(const BrickSource& source, std::uint32_t channel) {
  const auto& pyramid = dynamic_cast<const PyramidSource&>(source);
  const VolumeDesc& d = source.volume();
  std::vector<std::byte> bytes(d.voxel_count() * voxel_size(d.type));
  pyramid.read_level_box(0, channel, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)}, bytes);
  std::vector<double> v;
  v.reserve(d.voxel_count());
  for (std::size_t i = 0; i < d.voxel_count(); ++i) {
    if (d.type == VoxelType::u8) v.push_back(double(std::uint8_t(bytes[i])));
    if (d.type == VoxelType::u16) {
      std::uint16_t x;
      std::memcpy(&x, bytes.data() + 2 * i, 2);
      v.push_back(x);
    }
    if (d.type == VoxelType::f32) {
      float x;
      std::memcpy(&x, bytes.data() + 4 * i, 4);
      v.push_back(x);
    }
  }
  return v;
}

}  // namespace resoct
