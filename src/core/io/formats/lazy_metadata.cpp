#include "io/formats/lazy_metadata.hpp"

#include <algorithm>
#include <limits>

#include "io/formats/level0_scan.hpp"
#include "resoct/base/error.hpp"

namespace resoct::detail {

namespace {

/// Blocks of a block range, saturating instead of wrapping for absurd extents.
std::uint64_t block_count(const glm::u64vec3& n) {
  std::uint64_t c = n.x;
  if (n.y != 0 && c > std::numeric_limits<std::uint64_t>::max() / n.y) {
    return std::numeric_limits<std::uint64_t>::max();
  }
  c *= n.y;
  if (n.z != 0 && c > std::numeric_limits<std::uint64_t>::max() / n.z) {
    return std::numeric_limits<std::uint64_t>::max();
  }
  return c * n.z;
}

}  // namespace

LazyMetadata::LazyMetadata(const VolumeDesc& desc, LevelBoxReader level0, std::uint32_t block,
                           std::uint32_t query_blocks, std::uint64_t cache_entries)
    : desc_(desc),
      level0_(std::move(level0)),
      block_(block),
      query_blocks_(query_blocks),
      shard_capacity_(std::size_t(std::max<std::uint64_t>(1, cache_entries / kShards))),
      blocks_((desc.extent + glm::u64vec3(block - 1)) / std::uint64_t(block)) {
  for (std::uint32_t c = 0; c < desc_.channels; ++c) {
    luts_.push_back(occupancy_lut(desc_.type, desc_.range(c)));
  }
}

RegionMeta LazyMetadata::unknown(std::uint32_t channel) const {
  const double inf = std::numeric_limits<double>::infinity();
  RegionMeta m;
  switch (desc_.type) {
    case VoxelType::u8: m.min = 0.0, m.max = 255.0; break;
    case VoxelType::u16: m.min = 0.0, m.max = 65535.0; break;
    case VoxelType::f32: m.min = -inf, m.max = inf; break;
  }
  m.occupancy = occupancy_span(m.min, m.max, desc_.range(channel));
  return m;
}

bool LazyMetadata::lookup(const Key& k, RegionMeta& out) const {
  Shard& s = shard(k);
  const std::lock_guard lock(s.mutex);
  const auto it = s.entries.find(k);
  if (it == s.entries.end()) return false;
  out = it->second;
  return true;
}

void LazyMetadata::store(const Key& k, const RegionMeta& m) const {
  Shard& s = shard(k);
  const std::lock_guard lock(s.mutex);
  // Dropping a whole shard keeps memory bounded without per-entry recency bookkeeping; a dropped
  // summary is only recomputed when asked for again.
  if (s.entries.size() >= shard_capacity_) s.entries.clear();
  s.entries[k] = m;
}

RegionMeta LazyMetadata::query(std::uint32_t channel, const Box3& level0_region) const {
  const Box3 r = intersect(level0_region, Box3{glm::i64vec3(0), glm::i64vec3(desc_.extent)});
  if (r.empty()) return RegionMeta{};
  const auto bs = std::int64_t(block_);
  const glm::u64vec3 b0(r.lo / bs), b1((r.hi - std::int64_t(1)) / bs);
  // Looking blocks up is cheap but not free: past this many, answer without enumerating.
  const std::uint64_t enumerate_limit = std::uint64_t(query_blocks_) * 8u;
  if (block_count(b1 - b0 + std::uint64_t(1)) > enumerate_limit) return unknown(channel);

  RegionMeta acc;
  glm::u64vec3 m0(std::numeric_limits<std::uint64_t>::max()), m1(0);
  bool missing = false;
  for (std::uint64_t z = b0.z; z <= b1.z; ++z) {
    for (std::uint64_t y = b0.y; y <= b1.y; ++y) {
      for (std::uint64_t x = b0.x; x <= b1.x; ++x) {
        const glm::u64vec3 b(x, y, z);
        RegionMeta m;
        if (lookup(Key{linear(b), channel}, m)) {
          acc.merge(m);
        } else {
          missing = true;
          m0 = glm::min(m0, b);
          m1 = glm::max(m1, b);
        }
      }
    }
  }
  if (!missing) return acc;
  const glm::u64vec3 n = m1 - m0 + std::uint64_t(1);
  if (block_count(n) > query_blocks_) return unknown(channel);

  // One read of the bounding box of the missing blocks: a chunked reader serves it with one
  // decode per chunk instead of one per block.
  const Box3 box{glm::i64vec3(m0) * bs,
                 glm::min(glm::i64vec3(m1 + std::uint64_t(1)) * bs, glm::i64vec3(desc_.extent))};
  std::vector<std::byte> voxels(std::size_t(box.volume()) * voxel_size(desc_.type));
  std::vector<RegionMeta> metas(std::size_t(block_count(n)));
  try {
    level0_(channel, box, voxels);
  } catch (const Error&) {
    return unknown(channel);
  }
  block_metadata(desc_.type, box, voxels, desc_.range(channel), luts_[channel], block_, metas);
  computed_.fetch_add(metas.size(), std::memory_order_relaxed);
  for (std::uint64_t z = 0; z < n.z; ++z) {
    for (std::uint64_t y = 0; y < n.y; ++y) {
      for (std::uint64_t x = 0; x < n.x; ++x) {
        const glm::u64vec3 b = m0 + glm::u64vec3(x, y, z);
        const RegionMeta& m = metas[std::size_t((z * n.y + y) * n.x + x)];
        store(Key{linear(b), channel}, m);
        // The box lies inside the query's block range; blocks of it that were cached already
        // were merged above, and merging their exact summary again changes nothing.
        acc.merge(m);
      }
    }
  }
  return acc;
}

}  // namespace resoct::detail
