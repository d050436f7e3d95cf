#include "resoct/render/reference_voxels.hpp"

#include <memory>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"

namespace resoct::reference {

VoxelFunction level0_voxels(const BrickSource& source, std::span<const std::uint32_t> channels,
                            std::uint64_t max_bytes, const std::string& parameter,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const BrickHierarchy& h = source.hierarchy();
  const VolumeDesc& v = h.volume();
  const std::uint64_t voxels = v.extent.x * v.extent.y * v.extent.z;
  for (const std::uint32_t c : channels) {
    if (c >= v.channels) {
      throw invalid_parameter(parameter, "channel " + std::to_string(c) + " is not in the " +
                                             std::to_string(v.channels) + "-channel source");
    }
  }
  // Overflow-safe: voxels <= 2^51 (BrickKey axes) and at most 4096 channels.
  const long double need = (long double)voxels * 4.0L * (long double)channels.size();
  if (need > (long double)max_bytes) {
    throw invalid_parameter(
        parameter, "the dense reference needs " + std::to_string(std::uint64_t(need) >> 20) +
                       " MiB for level 0 of " + std::to_string(channels.size()) +
                       " channel(s), more than its limit of " + std::to_string(max_bytes >> 20) +
                       " MiB");
  }
  auto data = std::make_shared<std::vector<std::vector<float>>>(v.channels);
  for (const std::uint32_t c : channels) (*data)[c].assign(std::size_t(voxels), 0.0f);

  const LevelInfo& L = h.level(0);
  const std::uint32_t halo = h.layout().halo;
  const glm::uvec3 padded = h.layout().padded_size();
  const std::size_t vsize = voxel_size(v.type);
  std::vector<std::byte> brick(std::size_t(h.layout().padded_voxels()) * vsize);
  const std::uint64_t total = L.brick_count * channels.size();
  std::uint64_t done = 0;
  for (const std::uint32_t c : channels) {
    std::vector<float>& out = (*data)[c];
    for (std::uint32_t z = 0; z < L.bricks.z; ++z) {
      for (std::uint32_t y = 0; y < L.bricks.y; ++y) {
        for (std::uint32_t x = 0; x < L.bricks.x; ++x) {
          const glm::uvec3 b{x, y, z};
          source.read_brick(BrickKey(0, c, b), brick);
          const Box3 core = h.core_box(0, b);
          for (std::int64_t k = core.lo.z; k < core.hi.z; ++k) {
            for (std::int64_t j = core.lo.y; j < core.hi.y; ++j) {
              for (std::int64_t i = core.lo.x; i < core.hi.x; ++i) {
                const std::size_t src = ((std::size_t(k - core.lo.z) + halo) * padded.y +
                                         std::size_t(j - core.lo.y) + halo) *
                                            padded.x +
                                        std::size_t(i - core.lo.x) + halo;
                const std::size_t dst =
                    (std::size_t(k) * v.extent.y + std::size_t(j)) * v.extent.x + std::size_t(i);
                out[dst] = float(voxel_value(brick.data() + src * vsize, v.type));
              }
            }
          }
          ++done;
          if (progress) progress(done, total);
        }
      }
    }
  }
  const glm::u64vec3 extent = v.extent;
  return [extent, data](std::uint32_t channel, const glm::i64vec3& p) -> double {
    if (channel >= data->size() || (*data)[channel].empty()) {
      throw Error(ErrorCode::out_of_range,
                  "dense reference: channel " + std::to_string(channel) + " was not read");
    }
    const std::uint64_t i =
        (std::uint64_t(p.z) * extent.y + std::uint64_t(p.y)) * extent.x + std::uint64_t(p.x);
    return double((*data)[channel][std::size_t(i)]);
  };
}

}  // namespace resoct::reference
