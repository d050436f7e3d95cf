#include "resoct/sources/in_memory_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "resoct/volume/downsample.hpp"
#include "resoct/base/error.hpp"

namespace resoct {

namespace {

VolumeDesc checked_desc(const DenseVolume& v) {
  if (v.bytes().empty()) throw invalid_parameter("volume", "empty DenseVolume");
  return v.desc();
}

template <typename T>
void fill_metadata(const std::byte* data, const glm::u64vec3& e, const ValueRange& r,
                   std::uint32_t channel, MetadataPyramid& pyramid) {
  const std::uint64_t bs = pyramid.block_size();
  const glm::u64vec3 nb = pyramid.blocks();
  std::vector<RegionMeta> row(std::size_t(nb.x));
  // Integer types: one occupancy bit per possible value, looked up instead of recomputed.
  std::vector<std::uint32_t> lut;
  if constexpr (!std::is_same_v<T, float>) {
    lut.resize(std::size_t(std::numeric_limits<T>::max()) + 1u);
    for (std::size_t v = 0; v < lut.size(); ++v) lut[v] = occupancy_bit(double(v), r);
  }
  for (std::uint64_t z = 0; z < e.z; ++z) {
    for (std::uint64_t y = 0; y < e.y; ++y) {
      const std::byte* src = data + std::size_t((z * e.y + y) * e.x) * sizeof(T);
      for (std::uint64_t bx = 0; bx < nb.x; ++bx) {
        RegionMeta m;
        const std::uint64_t x1 = std::min(e.x, (bx + 1) * bs);
        for (std::uint64_t x = bx * bs; x < x1; ++x) {
          T v;
          std::memcpy(&v, src + x * sizeof(T), sizeof(T));
          const double d = double(v);
          if constexpr (std::is_same_v<T, float>) {
            if (std::isnan(d)) continue;
            m.occupancy |= occupancy_bit(d, r);
          } else {
            m.occupancy |= lut[std::size_t(v)];
          }
          m.min = std::min(m.min, d);
          m.max = std::max(m.max, d);
        }
        pyramid.merge_block(channel, {bx, y / bs, z / bs}, m);
      }
    }
  }
}

}  // namespace

InMemorySource::InMemorySource(DenseVolume volume, BrickLayout layout, std::uint32_t metadata_block,
                               std::string name)
    : volume_(std::move(volume)),
      hierarchy_(checked_desc(volume_), layout),
      name_(std::move(name)),
      pyramid_(volume_.desc().extent, metadata_block, volume_.desc().channels) {
  const VolumeDesc& d = volume_.desc();
  const std::size_t vs = voxel_size(d.type);
  coarse_.resize(hierarchy_.level_count() - 1u);
  for (std::uint32_t l = 1; l < hierarchy_.level_count(); ++l) {
    const LevelInfo& fine = hierarchy_.level(l - 1);
    const LevelInfo& coarse = hierarchy_.level(l);
    const glm::bvec3 halve = glm::greaterThan(coarse.factor_log2, fine.factor_log2);
    const std::size_t per_channel =
        std::size_t(coarse.extent.x * coarse.extent.y * coarse.extent.z) * vs;
    coarse_[l - 1].resize(per_channel * d.channels);
    for (std::uint32_t c = 0; c < d.channels; ++c) {
      downsample(level_voxels(l - 1, c), fine.extent, halve, d.type,
                 std::span<std::byte>(coarse_[l - 1]).subspan(c * per_channel, per_channel));
    }
  }
  for (std::uint32_t c = 0; c < d.channels; ++c) {
    const std::byte* data = volume_.channel_bytes(c).data();
    switch (d.type) {
      case VoxelType::u8:
        fill_metadata<std::uint8_t>(data, d.extent, d.range(c), c, pyramid_);
        break;
      case VoxelType::u16:
        fill_metadata<std::uint16_t>(data, d.extent, d.range(c), c, pyramid_);
        break;
      case VoxelType::f32: fill_metadata<float>(data, d.extent, d.range(c), c, pyramid_); break;
    }
  }
  pyramid_.build();
}

std::span<const std::byte> InMemorySource::level_voxels(std::uint32_t level,
                                                        std::uint32_t channel) const {
  if (level >= hierarchy_.level_count() || channel >= volume().channels) {
    throw Error(ErrorCode::out_of_range, name_ + ": no level " + std::to_string(level) +
                                             " channel " + std::to_string(channel));
  }
  if (level == 0) return volume_.channel_bytes(channel);
  const std::vector<std::byte>& all = coarse_[level - 1];
  const std::size_t n = all.size() / volume().channels;
  return std::span<const std::byte>(all).subspan(std::size_t(channel) * n, n);
}

void InMemorySource::read_brick(BrickKey key, std::span<std::byte> out) const {
  check_brick_request(key, out);
  const std::uint32_t l = key.level();
  const Box3 level_box{glm::i64vec3(0), glm::i64vec3(hierarchy_.level(l).extent)};
  copy_box_clamped(level_voxels(l, key.channel()), level_box, out,
                   hierarchy_.padded_box(l, key.brick()), voxel_size(volume().type));
}

RegionMeta InMemorySource::region_meta(std::uint32_t channel, const Box3& level0_region) const {
  if (channel >= volume().channels) {
    throw Error(ErrorCode::out_of_range, name_ +
                                             ": parameter 'channel': " + std::to_string(channel) +
                                             " of " + std::to_string(volume().channels));
  }
  return pyramid_.query(channel, level0_region);
}

}  // namespace resoct
