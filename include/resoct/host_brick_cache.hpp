#pragma once
/// \file
/// Host-side cache of decoded bricks between the BrickSource and the device cache: a brick that
/// was evicted from the device (or requested again after a camera move) is re-uploaded from host
/// memory instead of being read and decoded again.

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "resoct/brick_key.hpp"
#include "resoct/brick_source.hpp"

namespace resoct {

/// One decoded brick: its metadata and, unless the brick is constant, its padded voxels (a
/// constant brick needs no cache slot, so its voxels are not kept).
struct HostBrick {
  BrickKey key;
  BrickMeta meta;
  std::vector<std::byte> voxels;  ///< empty when meta.constant
};

struct HostBrickCacheStats {
  std::uint64_t hits = 0;
  std::uint64_t misses = 0;
  std::uint64_t insertions = 0;
  std::uint64_t evictions = 0;
};

/// LRU cache of HostBricks bounded by bytes. Each entry costs its voxel bytes plus
/// kEntryOverhead (so constant bricks are bounded too). A brick larger than the whole capacity
/// is not kept. Entries are shared_ptr<const>, so a brick handed out stays valid after eviction.
/// Thread-safety: every member may be called from any number of threads at once (one mutex).
class HostBrickCache {
 public:
  /// Accounted bytes of bookkeeping per entry.
  static constexpr std::uint64_t kEntryOverhead = 64;

  /// `capacity_bytes` 0 disables caching (put() keeps nothing).
  explicit HostBrickCache(std::uint64_t capacity_bytes);

  std::uint64_t capacity_bytes() const noexcept { return capacity_; }
  /// Accounted bytes of one brick: voxel bytes + kEntryOverhead.
  static std::uint64_t cost(const HostBrick& b) noexcept {
    return std::uint64_t(b.voxels.size()) + kEntryOverhead;
  }

  /// The brick, marked most recently used; nullptr when absent (counted as hit or miss).
  std::shared_ptr<const HostBrick> get(BrickKey key);
  /// True when present; does not change the use order or the statistics.
  bool contains(BrickKey key) const;
  /// Inserts or replaces a brick as most recently used, evicting least recently used entries
  /// until the total fits.
  void put(std::shared_ptr<const HostBrick> brick);
  void clear();

  std::uint64_t bytes() const;
  std::size_t size() const;
  HostBrickCacheStats stats() const;

 private:
  using Order = std::list<std::shared_ptr<const HostBrick>>;  // front: most recently used
  void evict_to_fit();                                        // caller holds mutex_

  std::uint64_t capacity_;
  mutable std::mutex mutex_;
  Order order_;
  std::unordered_map<BrickKey, Order::iterator> index_;
  std::uint64_t bytes_ = 0;
  HostBrickCacheStats stats_;
};

}  // namespace resoct
