#pragma once
/// \file
/// The per-frame set of missing-data requests: a bounded, deduplicated, lock-free hash set
/// (open addressing, compare-exchange, bounded probing; paper 002 §5.3) with a per-key hit count,
/// plus the greedy/global request strategies (paper 002 §5.3.2).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include "resoct/volume/hierarchy.hpp"
#include "resoct/engine/device_records.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/request_strategy.hpp"

namespace resoct {

/// What drain() hands out for one frame.
struct RequestBatch {
  std::vector<Request> requests;  ///< coarser level first, then more hits, then smaller key
  std::uint64_t dropped = 0;      ///< inserts refused because the set was full or probing gave up
};

/// Keys are 32-bit; kernel::RESOCT_REQUEST_KEY_NONE (all ones) marks a free slot and is refused.
/// Brick and node (metadata) requests live in two separate sets, so their key spaces never mix:
/// brick sets hold device request keys (kernel/request_key.glsl.h), node sets octree node indices.
///
/// Guarantees: a key is stored at most once; an insert either adds its hits to the key's count or
/// is counted in dropped() (so sum of hits + dropped inserts = inserts of one hit each); a refused
/// insert is never an error. Probing is linear from kernel::resoct_request_key_hash, at most
/// max_probes slots, so a GPU set built the same way behaves identically.
/// Thread-safety: insert() is lock-free and may run on any number of threads at once; every other
/// member must not overlap with insert() (call it between frames).
class RequestSet {
 public:
  using LevelFn = std::function<std::uint32_t(std::uint32_t key)>;

  /// `capacity` is rounded up to a power of two; throws Error(invalid_argument) naming
  /// "capacity" (must be 1..2^28) or "max_probes" (must be >= 1).
  explicit RequestSet(std::uint32_t capacity, std::uint32_t max_probes = 16);

  std::uint32_t capacity() const noexcept { return mask_ + 1u; }
  std::uint32_t max_probes() const noexcept { return max_probes_; }

  /// Adds `hits` to key's count, inserting it if absent. False (and counted) when the set is
  /// full, the probe bound is hit, or the key is the reserved RESOCT_REQUEST_KEY_NONE. Lock-free.
  /// Counts are 32-bit and wrap past 2^32 - 1 hits in one frame: insert once per ray, not per
  /// sample.
  bool insert(std::uint32_t key, std::uint32_t hits = 1) noexcept;

  /// Distinct keys stored this frame.
  std::uint32_t size() const noexcept { return filled_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

  /// Returns this frame's requests, sorted for loading (coarser level first via level_of, then
  /// descending hits, then ascending key), and empties the set. O(size log size).
  RequestBatch drain(const LevelFn& level_of);
  /// As drain(level_of) with every level 0: ordered by hits, then key.
  RequestBatch drain();
  /// Empties the set in O(size()): only the slots filled this frame are reset.
  void clear() noexcept;

 private:
  std::uint32_t mask_ = 0;
  std::uint32_t log2_capacity_ = 0;
  std::uint32_t max_probes_ = 0;
  std::unique_ptr<std::atomic<std::uint32_t>[]> keys_;
  std::unique_ptr<std::atomic<std::uint32_t>[]> hits_;
  std::unique_ptr<std::uint32_t[]> filled_slots_;  // slot of the i-th key stored this frame
  std::atomic<std::uint32_t> filled_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

/// The brick at coarser level `level` that contains `brick` of level `from` (level >= from).
/// Bricks of every level have the same core size and levels differ by powers of two per axis, so
/// a brick never straddles a coarser brick's border: the ancestor is brick >> (f_level - f_from).
glm::uvec3 coarser_brick(const BrickHierarchy& h, std::uint32_t from, const glm::uvec3& brick,
                         std::uint32_t level);

/// Bricks to request for a missing target: global yields the target; greedy yields the target and
/// its ancestors at each coarser level up to the coarsest, stopping before the first one for
/// which `available` (optional, e.g. a residency query) returns true. Target first.
std::vector<PageAddress> bricks_to_request(
    const BrickHierarchy& h, const PageAddress& target, RequestStrategy strategy,
    const std::function<bool(const PageAddress&)>& available = {});

}  // namespace resoct
