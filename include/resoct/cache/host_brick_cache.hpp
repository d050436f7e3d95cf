#pragma once
/// \file
/// Host-side cache of decoded bricks between the BrickSource and the device cache: a brick that
/// was evicted from the device (or requested again after a camera move) is re-uploaded from host
/// memory instead of being read and decoded again.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "resoct/volume/brick_key.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/cache/eviction_policy.hpp"
#include "resoct/volume/timed_brick_key.hpp"

namespace resoct {

/// One decoded brick: its metadata and, unless the brick is constant, its padded voxels (a
/// constant brick needs no cache slot, so its voxels are not kept).
struct HostBrick {
  BrickKey key;
  /// The timepoint it was read from (0 without a time axis): entries are keyed by both, so
  /// bricks of several timepoints (the shown one, the next one prefetched) live side by side.
  std::uint32_t timepoint = 0;
  BrickMeta meta;
  /// Down-sampling error in [0, 1] of the channel's range (brick_error()), measured when the
  /// loader measures errors (level >= 1); 1 = unknown.
  float error = 1.0f;
  std::vector<std::byte> voxels;  ///< empty when meta.constant
};

struct HostBrickCacheStats {
  std::uint64_t hits = 0;
  std::uint64_t misses = 0;
  std::uint64_t insertions = 0;
  std::uint64_t evictions = 0;
};

/// Cache of HostBricks bounded by bytes, with a pluggable EvictionPolicy (LruPolicy by default;
/// OctreemizerPolicy for the discard priority of paper 001). Each entry costs its voxel bytes plus
/// kEntryOverhead (so constant bricks are bounded too). A brick larger than the whole capacity is
/// not kept. Entries are shared_ptr<const>, so a brick handed out stays valid after eviction.
/// The policy sees each entry as a slot; nothing is pinned except the brick being inserted (a
/// host entry has no device copy in flight), and its ages are counted in the frames given by
/// set_frame(). Thread-safety: every member may be called from any number of threads at once
/// (one mutex, held while the policy runs).
class HostBrickCache {
 public:
  /// Accounted bytes of bookkeeping per entry.
  static constexpr std::uint64_t kEntryOverhead = 64;

  /// `capacity_bytes` 0 disables caching (put() keeps nothing). A null `policy` means LRU.
  explicit HostBrickCache(std::uint64_t capacity_bytes,
                          std::unique_ptr<EvictionPolicy> policy = nullptr);
  ~HostBrickCache();
  HostBrickCache(const HostBrickCache&) = delete;
  HostBrickCache& operator=(const HostBrickCache&) = delete;

  std::uint64_t capacity_bytes() const noexcept { return capacity_; }
  /// Accounted bytes of one brick: voxel bytes + kEntryOverhead.
  static std::uint64_t cost(const HostBrick& b) noexcept {
    return std::uint64_t(b.voxels.size()) + kEntryOverhead;
  }
  /// The policy's name ("lru", "octreemizer").
  std::string_view policy_name() const noexcept;

  /// The frame that later uses and insertions are recorded with (the renderer's frame).
  void set_frame(std::uint64_t frame);
  /// Tells the policy that its distances changed (EvictionPolicy::distances_changed).
  void distances_changed();

  /// The brick of `timepoint`, recorded as used; nullptr when absent (counted as hit or miss).
  std::shared_ptr<const HostBrick> get(BrickKey key, std::uint32_t timepoint = 0);
  /// True when present; does not change the use order or the statistics.
  bool contains(BrickKey key, std::uint32_t timepoint = 0) const;
  /// Inserts or replaces a brick (under its key and timepoint) as used now, then evicts the
  /// policy's victims until the total fits.
  void put(std::shared_ptr<const HostBrick> brick);
  void clear();

  std::uint64_t bytes() const;
  std::size_t size() const;
  HostBrickCacheStats stats() const;

 private:
  struct Entry {
    std::shared_ptr<const HostBrick> brick;  // null: free slot
    std::uint64_t last_frame = 0;            // for replaying the policy after growth
    std::uint64_t last_seq = 0;
  };
  std::uint32_t take_slot();            // caller holds mutex_
  void record_use(std::uint32_t slot);  // caller holds mutex_
  void remove_slot(std::uint32_t slot);
  void grow();
  void evict_to_fit();

  std::uint64_t capacity_;
  std::unique_ptr<EvictionPolicy> policy_;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;   // by policy slot
  std::vector<CacheSlot> pins_;  // last_use = operation sequence: only the current op pins
  std::vector<std::uint32_t> free_;
  std::unordered_map<TimedBrickKey, std::uint32_t> index_;
  std::uint64_t frame_ = 0;
  std::uint64_t seq_ = 0;
  std::uint64_t bytes_ = 0;
  HostBrickCacheStats stats_;
};

}  // namespace resoct
