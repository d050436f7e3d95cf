#pragma once
// Lazy region metadata of PyramidSource (internal): exact per-block summaries of level 0,
// computed on first need and cached, with a conservative "unknown" answer for queries that would
// read too much.

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "resoct/io/formats/pyramid_source.hpp"

namespace resoct::detail {

/// Thread-safety: query() may be called from any number of threads at once.
class LazyMetadata {
 public:
  /// `block` is the metadata block edge (a power of two), `query_blocks` the most unknown
  /// blocks one query reads, `cache_entries` the most cached block summaries.
  LazyMetadata(const VolumeDesc& desc, LevelBoxReader level0, std::uint32_t block,
               std::uint32_t query_blocks, std::uint64_t cache_entries);

  /// Conservative metadata of `channel` (valid) over the level-0 region: exact per-block
  /// summaries when every touched block is cached or the uncached ones fit the read budget,
  /// else unknown(channel). A level-0 read that throws Error also answers unknown(channel): the
  /// brick reads of the same voxels report the damage, and culling must not stall on it.
  RegionMeta query(std::uint32_t channel, const Box3& level0_region) const;

  /// The summary that claims nothing: the type's whole value range and every occupancy bin.
  RegionMeta unknown(std::uint32_t channel) const;

  std::uint64_t blocks_computed() const noexcept { return computed_.load(); }

 private:
  struct Key {
    std::uint64_t block;
    std::uint32_t channel;
    friend bool operator==(const Key&, const Key&) = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const noexcept {
      return std::size_t((k.block * 0x9e3779b97f4a7c15ull) ^ (std::uint64_t(k.channel) << 48) ^
                         (k.block >> 29));
    }
  };
  struct Shard {
    std::mutex mutex;
    std::unordered_map<Key, RegionMeta, KeyHash> entries;
  };
  static constexpr std::size_t kShards = 16;

  Shard& shard(const Key& k) const { return shards_[KeyHash{}(k) % kShards]; }
  bool lookup(const Key& k, RegionMeta& out) const;
  void store(const Key& k, const RegionMeta& m) const;
  std::uint64_t linear(const glm::u64vec3& b) const {
    return (b.z * blocks_.y + b.y) * blocks_.x + b.x;
  }

  VolumeDesc desc_;
  LevelBoxReader level0_;
  std::uint32_t block_;
  std::uint32_t query_blocks_;
  std::size_t shard_capacity_;
  glm::u64vec3 blocks_;
  std::vector<std::vector<std::uint32_t>> luts_;
  mutable std::array<Shard, kShards> shards_;
  mutable std::atomic<std::uint64_t> computed_{0};
};

}  // namespace resoct::detail
