#pragma once
/// \file
/// Host bookkeeping of the device brick cache: fixed-size slots (padded brick) of one voxel type,
/// slot <-> BrickKey, pinning, eviction through a pluggable policy, and the per-frame upload
/// budget. The voxel memory itself belongs to the backend.

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "resoct/volume/brick_key.hpp"
#include "resoct/cache/eviction_policy.hpp"
#include "resoct/engine/upload_budget.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

namespace detail {
/// BrickKey bits -> cache slot: open addressing with linear probing and backward-shift deletion,
/// load factor <= 1/2, so lookups, inserts and erases are O(1) expected without allocation.
class KeySlotIndex {
 public:
  static constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();
  void reset(std::uint32_t max_entries);
  std::optional<std::uint32_t> find(std::uint64_t key) const noexcept;
  void insert(std::uint64_t key, std::uint32_t slot) noexcept;  ///< key must be absent
  void erase(std::uint64_t key) noexcept;                       ///< no-op when absent

 private:
  struct Cell {
    std::uint64_t key = kEmpty;
    std::uint32_t slot = 0;
  };
  std::size_t home(std::uint64_t key) const noexcept;
  std::vector<Cell> cells_;
  std::size_t mask_ = 0;
};
}  // namespace detail

/// A slot given to a new brick, and the brick that was evicted to make room (its page-table entry
/// must become UNMAPPED and the residency octree must drop it).
struct CacheInsertion {
  std::uint32_t slot = 0;
  std::optional<BrickKey> evicted;
};

struct BrickCacheStats {
  std::uint64_t insertions = 0;
  std::uint64_t evictions = 0;
  std::uint64_t releases = 0;
  std::uint64_t allocation_failures = 0;  ///< insert() found every slot pinned
};

/// One pool: capacity_bytes / padded brick bytes slots. Frames are numbered by the caller and
/// must increase; insert() and touch() count as a use in the current frame. A brick used in the
/// current frame or uploaded fewer than `ttl` frames ago is pinned and never evicted; if no slot
/// can be freed, insert() returns nullopt and counts an allocation failure.
/// Thread-safety: none; the frame loop owns it.
class BrickCache {
 public:
  /// Throws Error(invalid_argument) naming "capacity_bytes" when it is 0, smaller than one padded
  /// brick, or yields more slots than a page entry can address (2^26); the layout is validated.
  /// Error(out_of_memory) when the host cannot hold the bookkeeping. `policy` defaults to
  /// LruPolicy.
  BrickCache(const BrickLayout& layout, VoxelType type, std::uint64_t capacity_bytes,
             std::uint32_t ttl = 2, std::unique_ptr<EvictionPolicy> policy = nullptr);

  std::uint32_t slot_count() const noexcept { return std::uint32_t(slots_.size()); }
  std::uint64_t slot_bytes() const noexcept { return slot_bytes_; }
  VoxelType voxel_type() const noexcept { return type_; }
  std::uint32_t ttl() const noexcept { return ttl_; }
  std::uint32_t resident_count() const noexcept { return resident_; }
  std::uint64_t frame() const noexcept { return frame_; }
  const BrickCacheStats& stats() const noexcept { return stats_; }
  EvictionPolicy& policy() noexcept { return *policy_; }

  /// Starts a frame; throws Error(invalid_argument) naming "frame" unless it exceeds the last one.
  void begin_frame(std::uint64_t frame);

  std::optional<std::uint32_t> find(BrickKey key) const;
  std::optional<BrickKey> key_of(std::uint32_t slot) const;
  bool pinned(std::uint32_t slot) const;

  /// Marks a resident slot used in the current frame. O(1) for LRU. Throws Error(out_of_range)
  /// for a free or out-of-range slot.
  void touch(std::uint32_t slot);

  /// Gives `key` a slot (a free one, else the policy's victim). A key that is already resident
  /// keeps its slot, counts as a use, and reports no eviction. nullopt when all slots are pinned.
  std::optional<CacheInsertion> insert(BrickKey key);

  /// Frees a slot (e.g. its channel left the visible slots). No-op for a free slot.
  void release(std::uint32_t slot);

 private:
  void check_resident(std::uint32_t slot) const;
  PinState pins() const noexcept { return {slots_.data(), frame_, ttl_}; }

  static constexpr std::uint64_t kFreeKey = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t slot_bytes_ = 0;
  VoxelType type_;
  std::uint32_t ttl_;
  std::unique_ptr<EvictionPolicy> policy_;
  std::uint64_t frame_ = 0;  // before the first begin_frame(), uses count as frame 0
  bool started_ = false;
  std::uint32_t resident_ = 0;
  std::vector<CacheSlot> slots_;     // key_bits == kFreeKey: free
  std::vector<std::uint32_t> free_;  // stack of free slots
  detail::KeySlotIndex index_;
  BrickCacheStats stats_;
};

/// One brick waiting for upload and the bytes it costs (0 for page-only updates such as EMPTY).
struct UploadCandidate {
  BrickKey key;
  std::uint64_t bytes = 0;
};

struct UploadPlan {
  std::vector<UploadCandidate> admitted;
  std::vector<UploadCandidate> deferred;
  std::uint64_t admitted_bytes = 0;
};

/// Admits candidates in the given (priority) order while both budgets hold; every candidate counts
/// one brick. The first candidate that does not fit and everything after it are deferred, so that
/// priority order is never overtaken by a smaller, later brick.
UploadPlan plan_uploads(std::span<const UploadCandidate> in_priority_order,
                        const UploadBudget& budget);

}  // namespace resoct
