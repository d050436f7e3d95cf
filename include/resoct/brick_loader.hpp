#pragma once
/// \file
/// Asynchronous brick loading: a thread pool reads bricks from a BrickSource (through a
/// HostBrickCache) in priority order and hands decoded bricks to the frame loop.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "resoct/brick_key.hpp"
#include "resoct/brick_source.hpp"
#include "resoct/host_brick_cache.hpp"

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
  LoadRequest request() const { return {brick->key, hits, since, rank}; }
};

/// A brick that could not be loaded; reported once.
struct LoadFailure {
  BrickKey key;
  std::string message;  ///< "<source name>: brick level L channel C (x, y, z): <reason>"
};

struct BrickLoaderStats {
  std::uint64_t loads = 0;       ///< bricks read from the source
  std::uint64_t host_hits = 0;   ///< bricks served by the host cache
  std::uint64_t failures = 0;    ///< distinct bricks that failed
  std::uint64_t cancelled = 0;   ///< queued requests dropped because a newer list omitted them
  std::uint64_t duplicates = 0;  ///< requests ignored: already queued, in flight, ready or failed
};

/// Loading order: coarser level first, then lower channel rank, then older (smaller `since`),
/// then more hits, then smaller key (deterministic).
bool load_before(const LoadRequest& a, const LoadRequest& b) noexcept;

/// Loads bricks in priority order. request() replaces the set of queued (not yet started)
/// requests; bricks already in flight finish and are delivered; a key is queued, loading or ready
/// at most once; a key that failed is never loaded again. With 0 threads nothing happens in the
/// background and run_queued() loads on the calling thread, which makes tests deterministic.
/// Thread-safety: all members may be called from any thread; the worker threads are internal.
class BrickLoader {
 public:
  /// Throws Error(invalid_argument) naming "source" when it is null or "threads" above 1024.
  BrickLoader(std::shared_ptr<const BrickSource> source, std::uint32_t threads,
              std::uint64_t host_cache_bytes);
  /// Stops the workers after their current brick; queued requests are dropped.
  ~BrickLoader();
  BrickLoader(const BrickLoader&) = delete;
  BrickLoader& operator=(const BrickLoader&) = delete;

  std::uint32_t thread_count() const noexcept { return std::uint32_t(workers_.size()); }
  const BrickSource& source() const noexcept { return *source_; }

  /// The new queue: `wanted` minus keys in flight, ready or failed, deduplicated, in load_before
  /// order. Queued keys not in `wanted` are cancelled.
  void request(std::span<const LoadRequest> wanted);
  /// Loads up to `max` queued bricks on the calling thread, best first; returns how many.
  std::size_t run_queued(std::size_t max);
  /// Blocks until nothing is queued or in flight (for tools and tests with threads).
  void wait_idle();

  /// Loaded bricks not yet taken, in load_before order; the ready list is emptied.
  std::vector<LoadedBrick> take_ready();
  /// Failures since the last call; each failed key appears exactly once over all calls.
  std::vector<LoadFailure> take_failures();
  bool has_failed(BrickKey key) const;

  std::size_t queued() const;
  std::size_t in_flight() const;
  std::size_t ready() const;
  /// Nothing queued, in flight or ready.
  bool idle() const;

  HostBrickCache& host_cache() noexcept { return cache_; }
  BrickLoaderStats stats() const;

 private:
  void worker_main();
  /// Pops the best queued request; caller holds mutex_ and the queue is not empty.
  LoadRequest pop_locked();
  /// Loads one brick without holding mutex_ and files the result.
  void load_one(const LoadRequest& r);

  std::shared_ptr<const BrickSource> source_;
  HostBrickCache cache_;
  mutable std::mutex mutex_;
  std::condition_variable work_cv_;
  std::condition_variable idle_cv_;
  bool stop_ = false;
  std::vector<LoadRequest> queue_;  // sorted so that back() loads first
  std::unordered_set<BrickKey> queued_keys_;
  std::unordered_set<BrickKey> in_flight_;
  std::unordered_map<BrickKey, LoadedBrick> ready_;
  std::unordered_set<BrickKey> failed_;
  std::vector<LoadFailure> new_failures_;
  BrickLoaderStats stats_;
  std::vector<std::thread> workers_;
};

}  // namespace resoct
