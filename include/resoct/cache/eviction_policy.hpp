#pragma once
/// \file
/// Pluggable brick-cache eviction: the interface, LRU by last use, and the Octreemizer discard
/// priority (Plate et al. 2002). See docs/core-structures.md for complexity.

#include <cstdint>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/cache/eviction.hpp"
#include "resoct/volume/brick_key.hpp"
#include "resoct/volume/hierarchy.hpp"

namespace resoct {

/// The cache's record of one slot, 32 bytes so that a touch reads one cache line.
struct alignas(32) CacheSlot {
  std::uint64_t key_bits = 0;  ///< BrickKey bits, or all ones when the slot is free
  std::uint64_t last_use = 0;  ///< frame of the last use
  std::uint64_t uploaded = 0;  ///< frame of the upload
};

/// The cache's pinning rule, handed to policies: a slot is pinned while it was used in the
/// current frame or was uploaded fewer than `ttl` frames ago (frame < uploaded + ttl).
struct PinState {
  const CacheSlot* slots = nullptr;
  std::uint64_t frame = 0;
  std::uint32_t ttl = 0;
  std::uint64_t last_use(std::uint32_t slot) const noexcept { return slots[slot].last_use; }
  bool pinned(std::uint32_t slot) const noexcept {
    return slots[slot].last_use == frame || frame < slots[slot].uploaded + ttl;
  }
};

/// Orders resident slots for eviction. The cache calls the hooks; victim() proposes an unpinned
/// resident slot (it is removed only when the cache then calls on_remove). Within one frame the
/// pin state of a slot can only go from unpinned to pinned (by a use), which policies may rely on
/// to skip pinned slots once per frame. Thread-safety: none (owned by one BrickCache).
class EvictionPolicy {
 public:
  virtual ~EvictionPolicy() = default;
  /// Forget everything; slots are 0 .. slot_count - 1.
  virtual void reset(std::uint32_t slot_count) = 0;
  virtual void begin_frame(std::uint64_t frame) = 0;
  virtual void on_insert(std::uint32_t slot, BrickKey key, std::uint64_t frame) = 0;
  virtual void on_touch(std::uint32_t slot, std::uint64_t frame) = 0;
  virtual void on_remove(std::uint32_t slot) = 0;
  /// An unpinned resident slot to evict, or nullopt when every resident slot is pinned.
  virtual std::optional<std::uint32_t> victim(const PinState& pins) = 0;
  virtual std::string_view name() const noexcept = 0;
  /// What the policy's distances are measured to changed (a new wish list, a camera move): a
  /// policy that ranks by distance re-reads every resident slot's distance before its next
  /// victim. No-op for the others.
  virtual void distances_changed() {}
};

/// Least recently used: an intrusive doubly-linked list in use order. Touch, insert, remove O(1);
/// victim O(1) amortized: a per-frame cursor skips the slots pinned by ttl once per frame, and a
/// slot used in this frame ends the search (everything behind it was used this frame too).
/// Ties in last-use frame are broken by the first use within that frame.
class LruPolicy final : public EvictionPolicy {
 public:
  void reset(std::uint32_t slot_count) override;
  void begin_frame(std::uint64_t frame) override;
  void on_insert(std::uint32_t slot, BrickKey key, std::uint64_t frame) override;
  void on_touch(std::uint32_t slot, std::uint64_t frame) override;
  void on_remove(std::uint32_t slot) override;
  std::optional<std::uint32_t> victim(const PinState& pins) override;
  std::string_view name() const noexcept override { return "lru"; }

 private:
  void unlink(std::uint32_t slot);
  void append(std::uint32_t slot);

  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  struct Link {
    std::uint32_t prev = kNone, next = kNone;
  };
  std::vector<Link> links_;
  std::uint32_t head_ = kNone, tail_ = kNone;
  std::uint32_t cursor_ = kNone;  // first slot not yet known to be pinned in this frame
};

/// Octreemizer discard priority p = ka * age + kl * depth + kd * distance; the slot with the
/// largest p is evicted. age = frames since last use; depth = (level_count - 1) - level, i.e. 0
/// for the coarsest level, so that like the Octreemizer's octree level it grows towards finer
/// data and finer bricks go first; distance = whatever the policy's DistanceFn returns: the
/// published one is the neighbourhood distance in bricks to the wish list tree
/// (WishListDistance, Eviction::octreemizer), the named variant the camera distance
/// (brick_camera_distance, Eviction::octreemizer_camera). Defaults are the paper's ka = 1,
/// kl = 16, kd = 1.
struct OctreemizerWeights {
  double ka = 1.0;
  double kl = 16.0;
  double kd = 1.0;
};

/// Distance from a camera (physical coordinates: level-0 voxel units times spacing, origin at the
/// volume's corner) to the centre of a brick's level-0 footprint; a ready-made distance for
/// OctreemizerPolicy. Throws Error(out_of_range) for a key outside the hierarchy.
double brick_camera_distance(const BrickHierarchy& h, BrickKey key, const glm::dvec3& camera);

/// Indexed binary max-heap on the frame-independent part of p (ka * frame is common to all
/// slots, so q = kl * depth + kd * distance - ka * last_use orders like p). Touch, insert, remove
/// and distance updates O(log n); victim O(log n) amortized: pinned slots found at the top are
/// parked for the rest of the frame and return to the heap at the next begin_frame().
/// Distances come from `distance` (called on insert and on every touch, and for every resident
/// slot before the first victim after distances_changed(), which rebuilds the heap in O(n)) or
/// from set_distance().
class OctreemizerPolicy final : public EvictionPolicy {
 public:
  using DistanceFn = std::function<double(BrickKey)>;
  /// Throws Error(invalid_argument) naming "level_count" (must be 1..32) or a weight that is
  /// negative or not finite.
  OctreemizerPolicy(std::uint32_t level_count, OctreemizerWeights weights = {},
                    DistanceFn distance = {});

  void reset(std::uint32_t slot_count) override;
  void begin_frame(std::uint64_t frame) override;
  void on_insert(std::uint32_t slot, BrickKey key, std::uint64_t frame) override;
  void on_touch(std::uint32_t slot, std::uint64_t frame) override;
  void on_remove(std::uint32_t slot) override;
  std::optional<std::uint32_t> victim(const PinState& pins) override;
  std::string_view name() const noexcept override { return "octreemizer"; }
  void distances_changed() override { stale_ = true; }

  /// Sets a resident slot's distance (ignored for free slots).
  void set_distance(std::uint32_t slot, double distance);
  /// p of a resident slot at `frame` (for diagnostics and tests).
  double priority(std::uint32_t slot, std::uint64_t frame) const;

 private:
  struct HeapItem {
    double rank;  // q of the slot, cached so that sifting reads only the heap array
    std::uint32_t slot;
  };
  struct Entry {
    BrickKey key;
    std::uint64_t last_use = 0;
    double distance = 0.0;
  };
  double rank(std::uint32_t slot) const;  // q
  void heap_push(std::uint32_t slot);
  void heap_erase(std::uint32_t slot);
  void heap_fix(std::uint32_t slot);
  void sift_up(std::size_t i);
  void sift_down(std::size_t i);
  void place(std::size_t i, const HeapItem& item);
  void refresh_distances();

  static constexpr std::uint32_t kAbsent = 0xFFFFFFFFu;
  static constexpr std::uint32_t kParked = 0xFFFFFFFEu;
  std::uint32_t level_count_;
  OctreemizerWeights w_;
  DistanceFn distance_fn_;
  std::vector<Entry> entries_;
  std::vector<std::uint32_t> pos_;  // heap position, kAbsent (free) or kParked
  std::vector<HeapItem> heap_;
  std::vector<std::uint32_t> parked_;
  bool stale_ = false;  // distances_changed() since the last refresh
};

}  // namespace resoct
