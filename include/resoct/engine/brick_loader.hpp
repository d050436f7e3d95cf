#pragma once
/// \file
/// Asynchronous brick loading: a thread pool reads bricks from a BrickSource (through a
/// HostBrickCache) in priority order and hands decoded bricks to the frame loop.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/brick_key.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/cache/eviction_policy.hpp"
#include "resoct/cache/host_brick_cache.hpp"
#include "resoct/engine/leaf_scan.hpp"
#include "resoct/engine/load_failure.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/volume/timed_brick_key.hpp"
#include "resoct/sources/timepoint_sources.hpp"

namespace resoct {

/// One brick the frame loop wants, with its screen coverage (request hits).
struct LoadRequest {
  BrickKey key;
  std::uint32_t hits = 0;
  /// Frame in which the brick was first requested without interruption; older requests of a
  /// level go first, so that a cache too small for the working set still serves every brick.
  std::uint64_t since = 0;
  /// Channel rank (the scene's importance order): within a level, lower ranks load first.
  std::uint32_t rank = 0;
};

/// A loaded brick and the hits of the request that asked for it.
struct LoadedBrick {
  std::shared_ptr<const HostBrick> brick;
  std::uint32_t hits = 0;
  std::uint64_t since = 0;
  std::uint32_t rank = 0;
  /// A level-0 brick's exact leaf records (scan_leaves over its voxels), computed on the loading
  /// thread for the octree whose leaves are `leaf_size` voxels (BrickLoader's `leaf_layout`);
  /// leaf_size 0: not computed (constant bricks, level > 0, no layout).
  std::vector<LeafScan> leaves;
  glm::uvec3 leaf_size{0};
  LoadRequest request() const { return {brick->key, hits, since, rank}; }
};

struct BrickLoaderStats {
  std::uint64_t loads = 0;       ///< bricks read from the source
  std::uint64_t host_hits = 0;   ///< bricks served by the host cache
  std::uint64_t failures = 0;    ///< distinct bricks that failed
  std::uint64_t cancelled = 0;   ///< queued requests dropped because a newer list omitted them
  std::uint64_t duplicates = 0;  ///< requests ignored: already queued, in flight, ready or failed
  std::uint64_t prefetched = 0;  ///< bricks read into the host cache by prefetch()
  std::uint64_t prefetch_hits = 0;  ///< requests served by the host cache thanks to a prefetch
  /// Loads of an earlier timepoint that completed after set_timepoint() switched away: never
  /// delivered (their bricks stay in the host cache under their own timepoint).
  std::uint64_t stale_dropped = 0;
  std::uint64_t timepoint_switches = 0;  ///< set_timepoint() calls that changed the timepoint
  /// Failed bricks let through again by the transient-failure retry (set_transient_retry).
  std::uint64_t retries = 0;
};

/// Loading order: coarser level first, then lower channel rank, then older (smaller `since`),
/// then more hits, then smaller key (deterministic).
bool load_before(const LoadRequest& a, const LoadRequest& b) noexcept;

/// Loads bricks in priority order. request() replaces the set of queued (not yet started)
/// requests; bricks already in flight finish and are delivered; a key is queued, loading or ready
/// at most once; a key that failed is not loaded again, unless its failure may pass and
/// set_transient_retry() allows retries (below). prefetch() keeps a second, lower
/// priority queue whose bricks go into the host cache only (a worker takes one only while no
/// request is queued). With 0 threads nothing happens in the background and run_queued() /
/// run_prefetch() load on the calling thread, which makes tests deterministic.
///
/// Time series: requests, ready bricks and failures belong to the current timepoint
/// (set_timepoint()); switching drops them, and loads of the old timepoint still running are
/// marked stale and never delivered, so the frame loop can never receive a brick of another
/// timepoint than the one it renders. Prefetch keys carry their timepoint (the next one while
/// playing). The host cache keys bricks by (key, timepoint).
/// Thread-safety: all members may be called from any thread; the worker threads are internal.
class BrickLoader {
 public:
  /// Throws Error(invalid_argument) naming "source" when it is null or "threads" above 1024.
  /// `host_policy` orders host cache evictions (null: LRU). With a `leaf_layout` (the residency
  /// octree's), every level-0 brick that is not constant is delivered with its leaves' exact
  /// records (LoadedBrick::leaves, scan_leaves over the channel's range), computed on the loading
  /// thread so that the frame thread only stores them. With `measure_errors`, every brick of
  /// level >= 1 is delivered with its down-sampling error (HostBrick::error, brick_error()),
  /// also measured on the loading thread; it reads the level-0 bricks under the brick.
  BrickLoader(std::shared_ptr<const BrickSource> source, std::uint32_t threads,
              std::uint64_t host_cache_bytes, std::unique_ptr<EvictionPolicy> host_policy = nullptr,
              std::shared_ptr<const OctreeLayout> leaf_layout = nullptr,
              bool measure_errors = false);
  /// Stops the workers after their current brick; queued requests are dropped.
  ~BrickLoader();
  BrickLoader(const BrickLoader&) = delete;
  BrickLoader& operator=(const BrickLoader&) = delete;

  std::uint32_t thread_count() const noexcept { return std::uint32_t(workers_.size()); }
  /// The series' source as given to the constructor.
  const BrickSource& source() const noexcept { return *sources_->series(); }
  /// The series' timepoint sources (shared with the renderer for region metadata).
  TimepointSources& timepoint_sources() noexcept { return *sources_; }
  /// The timepoint requests are loaded from (initially the source's own).
  std::uint32_t timepoint() const;
  /// Makes `t` the current timepoint: queued and ready requests, adoptions and the failed set
  /// (failures are per timepoint) are dropped, loads in flight become stale (completed into the
  /// host cache, never delivered). Nothing happens when t is already current. Throws as
  /// TimepointSources::at (Error naming "timepoint" when t >= timepoints()), changing nothing.
  void set_timepoint(std::uint32_t t);

  /// The new queue: `wanted` minus keys in flight, ready or failed, deduplicated, in load_before
  /// order. Queued keys not in `wanted` are cancelled.
  void request(std::span<const LoadRequest> wanted);
  /// Loads up to `max` queued bricks on the calling thread, best first; returns how many.
  std::size_t run_queued(std::size_t max);
  /// Replaces the prefetch queue with `keys` (best first). Keys already in the host cache,
  /// queued, in flight, ready or failed are skipped. A prefetched brick goes into the host cache
  /// only; if a request() for it arrives while it loads, it is delivered like a requested one.
  /// A prefetch that fails marks the key failed and is reported like a failed request.
  void prefetch(std::span<const BrickKey> keys);
  /// The same with keys of any timepoint (the next one while playing). A prefetch of another
  /// than the current timepoint that fails is not recorded: a later request reports it.
  void prefetch(std::span<const TimedBrickKey> keys);
  /// Loads up to `max` prefetch keys on the calling thread; returns how many were loaded.
  std::size_t run_prefetch(std::size_t max);
  std::size_t prefetch_queued() const;
  /// Blocks until nothing is queued or in flight, prefetches and stale loads included (for tools
  /// and tests with threads).
  void wait_idle();

  /// Loaded bricks not yet taken, in load_before order; the ready list is emptied.
  std::vector<LoadedBrick> take_ready();
  /// Failures since the last call; each failed key appears exactly once over all calls, also
  /// when a retry fails again.
  std::vector<LoadFailure> take_failures();
  /// True when `key` failed and may not be requested now (a retry that is due is false).
  bool has_failed(BrickKey key) const;

  /// Retries of failures that may pass: an I/O error, a truncated transfer (a network or server
  /// fault: ErrorCode io or truncated) or exhausted host memory. Such a key is let through again
  /// `first` after it failed, then after twice as long each time it fails again, up to 32
  /// times `first`. Corrupt data and other errors are never retried. 0 (the default) never
  /// retries anything, so a failure is final. Throws Error(invalid_argument) naming
  /// "retry_after_ms" above one hour.
  void set_transient_retry(std::chrono::milliseconds first);
  /// Failed keys that will be let through again (they keep a renderer from converging).
  std::size_t retries_pending() const;

  std::size_t queued() const;
  std::size_t in_flight() const;
  std::size_t ready() const;
  /// Nothing queued, in flight or ready (prefetches do not count: they change no image).
  bool idle() const;

  HostBrickCache& host_cache() noexcept { return cache_; }
  const HostBrickCache& host_cache() const noexcept { return cache_; }
  BrickLoaderStats stats() const;

 private:
  void worker_main();
  /// A request popped with the timepoint generation it belongs to.
  struct Job {
    LoadRequest request;
    std::uint32_t timepoint = 0;
    std::uint64_t generation = 0;
    std::shared_ptr<const BrickSource> source;
  };
  /// Pops the best queued request; caller holds mutex_ and the queue is not empty.
  Job pop_locked();
  /// Pops the next prefetch key still worth loading and marks it loading; caller holds mutex_.
  std::optional<TimedBrickKey> pop_prefetch_locked();
  /// True when nothing needs loading for `k` (queued, loading, ready, failed or cached);
  /// caller holds mutex_.
  bool known_locked(const TimedBrickKey& k) const;
  /// Loads one brick without holding mutex_ and files the result (or drops it as stale).
  void load_one(const Job& job);
  /// Reads a brick of `source` (timepoint `t`) into the host cache; the failure message when it
  /// throws.
  std::shared_ptr<const HostBrick> read_brick(const BrickSource& source, BrickKey key,
                                              std::uint32_t t, std::string& failure,
                                              bool& transient);
  /// Loads one prefetch key without holding mutex_.
  void prefetch_one(const TimedBrickKey& key);
  /// Files a failure of `key` (current timepoint): marks it failed, schedules its retry when
  /// `transient` and retries are on, and reports it unless it was reported before. Caller holds
  /// mutex_.
  void fail_locked(BrickKey key, std::string failure, bool transient);
  /// The delivery of `brick` for request `r`, with its leaves' records where they apply
  /// (scanned by the calling thread; call without mutex_).
  LoadedBrick deliver(std::shared_ptr<const HostBrick> brick, const LoadRequest& r) const;
  /// Lets the failed keys whose retry is due through again. Caller holds mutex_.
  void release_due_retries_locked();
  /// When a failed key may be loaded again, and how often it failed.
  struct Retry {
    std::chrono::steady_clock::time_point due;
    std::uint32_t attempts = 0;
  };

  std::shared_ptr<TimepointSources> sources_;
  std::shared_ptr<const OctreeLayout> leaf_layout_;  // set once, before the workers start
  bool measure_errors_ = false;                      // likewise
  std::shared_ptr<const BrickSource> current_;       // source of timepoint_
  std::uint32_t timepoint_ = 0;
  // Bumped by every switch: a job of an older generation is stale when it completes.
  std::uint64_t generation_ = 0;
  std::size_t stale_in_flight_ = 0;
  HostBrickCache cache_;
  mutable std::mutex mutex_;
  std::condition_variable work_cv_;
  std::condition_variable idle_cv_;
  bool stop_ = false;
  std::vector<LoadRequest> queue_;  // sorted so that back() loads first
  std::unordered_set<BrickKey> queued_keys_;
  std::unordered_set<BrickKey> in_flight_;
  std::unordered_map<BrickKey, LoadedBrick> ready_;
  std::unordered_set<BrickKey> failed_;    // not to be loaded (now)
  std::unordered_set<BrickKey> reported_;  // failures reported, each once
  std::unordered_map<BrickKey, Retry> retry_;
  std::chrono::milliseconds retry_first_{0};
  std::deque<TimedBrickKey> prefetch_;  // front loads first
  std::unordered_set<TimedBrickKey> prefetching_;
  std::unordered_set<TimedBrickKey> prefetched_;  // in the host cache by prefetch, not requested
  // Requested while their prefetch was loading: delivered when it completes, not read twice.
  std::unordered_map<BrickKey, LoadRequest> adopted_;
  std::vector<LoadFailure> new_failures_;
  BrickLoaderStats stats_;
  std::vector<std::thread> workers_;
};

}  // namespace resoct
