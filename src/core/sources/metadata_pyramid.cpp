#include "resoct/sources/metadata_pyramid.hpp"

#include <cmath>
#include <cstring>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {
std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) {
  return a / b + (a % b != 0);
}
// Query cost bound: a region is answered from the finest pyramid level at which it touches at
// most this many entries, so queries cost O(1) regardless of region size.
constexpr std::uint64_t kMaxQueryEntries = 64;
}  // namespace

MetadataPyramid::MetadataPyramid(glm::u64vec3 extent0, std::uint32_t block_size,
                                 std::uint32_t channels)
    : extent0_(extent0), block_size_(block_size), channels_(channels) {
  if (block_size < 4 || block_size > 1024 || (block_size & (block_size - 1)) != 0) {
    throw invalid_parameter("metadata_block",
                            "must be a power of two in 4..1024, got " + std::to_string(block_size));
  }
  if (channels == 0) throw invalid_parameter("channels", "must be at least 1");
  glm::u64vec3 dim;
  for (int i = 0; i < 3; ++i) dim[i] = std::max<std::uint64_t>(1, ceil_div(extent0[i], block_size));
  for (;;) {
    Level lv;
    lv.dim = dim;
    lv.entries.resize(std::size_t(channels) * dim.x * dim.y * dim.z);
    levels_.push_back(std::move(lv));
    if (dim == glm::u64vec3(1)) break;
    for (int i = 0; i < 3; ++i) dim[i] = ceil_div(dim[i], 2);
  }
}

std::size_t MetadataPyramid::index(const Level& lv, std::uint32_t channel,
                                   const glm::u64vec3& b) const {
  return std::size_t(((channel * lv.dim.z + b.z) * lv.dim.y + b.y) * lv.dim.x + b.x);
}

std::span<RegionMeta> MetadataPyramid::finest(std::uint32_t channel) {
  Level& lv = levels_.at(0);
  const std::size_t n = std::size_t(lv.dim.x * lv.dim.y * lv.dim.z);
  return std::span<RegionMeta>(lv.entries).subspan(std::size_t(channel) * n, n);
}

std::span<const RegionMeta> MetadataPyramid::finest(std::uint32_t channel) const {
  const Level& lv = levels_.at(0);
  const std::size_t n = std::size_t(lv.dim.x * lv.dim.y * lv.dim.z);
  return std::span<const RegionMeta>(lv.entries).subspan(std::size_t(channel) * n, n);
}

void MetadataPyramid::merge_block(std::uint32_t channel, const glm::u64vec3& block,
                                  const RegionMeta& m) {
  Level& lv = levels_.at(0);
  lv.entries.at(index(lv, channel, block)).merge(m);
}

void MetadataPyramid::build() {
  for (std::size_t k = 1; k < levels_.size(); ++k) {
    const Level& fine = levels_[k - 1];
    Level& coarse = levels_[k];
    std::fill(coarse.entries.begin(), coarse.entries.end(), RegionMeta{});
    for (std::uint32_t c = 0; c < channels_; ++c) {
      for (std::uint64_t z = 0; z < fine.dim.z; ++z) {
        for (std::uint64_t y = 0; y < fine.dim.y; ++y) {
          for (std::uint64_t x = 0; x < fine.dim.x; ++x) {
            coarse.entries[index(coarse, c, {x / 2, y / 2, z / 2})].merge(
                fine.entries[index(fine, c, {x, y, z})]);
          }
        }
      }
    }
  }
}

RegionMeta MetadataPyramid::query(std::uint32_t channel, const Box3& level0_region) const {
  if (levels_.empty() || channel >= channels_) return {};
  const Box3 r = intersect(level0_region, Box3{glm::i64vec3(0), glm::i64vec3(extent0_)});
  if (r.empty()) return {};
  for (std::size_t k = 0; k < levels_.size(); ++k) {
    const Level& lv = levels_[k];
    const std::uint64_t span = std::uint64_t(block_size_) << k;
    glm::u64vec3 lo, hi;
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::uint64_t(r.lo[i]) / span;
      hi[i] = std::min(ceil_div(std::uint64_t(r.hi[i]), span), lv.dim[i]);
    }
    const std::uint64_t count = (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
    if (count > kMaxQueryEntries && k + 1 < levels_.size()) continue;
    RegionMeta out;
    for (std::uint64_t z = lo.z; z < hi.z; ++z) {
      for (std::uint64_t y = lo.y; y < hi.y; ++y) {
        for (std::uint64_t x = lo.x; x < hi.x; ++x)
          out.merge(lv.entries[index(lv, channel, {x, y, z})]);
      }
    }
    return out;
  }
  return {};
}

namespace {
template <typename T>
RegionMeta scan_typed(std::span<const std::byte> bytes, const ValueRange& r) {
  RegionMeta m;
  const std::size_t n = bytes.size() / sizeof(T);
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
    const double d = double(v);
    if (std::isnan(d)) continue;
    m.min = d < m.min ? d : m.min;
    m.max = d > m.max ? d : m.max;
    m.occupancy |= occupancy_bit(d, r);
  }
  return m;
}
}  // namespace

RegionMeta scan_region(std::span<const std::byte> voxels, VoxelType t, const ValueRange& r) {
  switch (t) {
    case VoxelType::u8: return scan_typed<std::uint8_t>(voxels, r);
    case VoxelType::u16: return scan_typed<std::uint16_t>(voxels, r);
    case VoxelType::f32: return scan_typed<float>(voxels, r);
  }
  return {};
}

}  // namespace resoct
