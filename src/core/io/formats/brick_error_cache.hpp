#pragma once
// Measured down-sampling errors kept by a source that computes its levels (PyramidSource, and so
// OME-Zarr, NIfTI, NRRD, TIFF): a coarse brick is measured once per source, not each time it is
// loaded again after the host cache evicted it (internal; BrickSource::brick_error).

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <unordered_map>

#include "resoct/volume/brick_key.hpp"

namespace resoct::detail {

/// Thread-safety: every member may be called from any number of threads at once.
class BrickErrorCache {
 public:
  /// Keeps at most about `entries` errors (at least one per shard); a full shard is dropped
  /// whole, as the lazy metadata cache does: errors are cheap to measure again, and an LRU
  /// order would cost a list per entry.
  explicit BrickErrorCache(std::uint64_t entries);

  /// The cached error of `key`, else `measure()`, cached and returned. The measurement runs
  /// outside the lock, so two threads that miss the same key both measure it (same value); an
  /// exception of `measure` caches nothing.
  template <class Measure>
  double get(BrickKey key, Measure&& measure) const {
    double e = 0.0;
    if (lookup(key, e)) return e;
    e = measure();
    store(key, e);
    return e;
  }

  /// Errors measured so far (misses), for tests and statistics.
  std::uint64_t measured() const noexcept { return measured_.load(); }

 private:
  struct Shard {
    std::mutex mutex;
    std::unordered_map<BrickKey, double> entries;
  };
  static constexpr std::size_t kShards = 16;

  Shard& shard(BrickKey key) const { return shards_[std::hash<BrickKey>{}(key) % kShards]; }
  bool lookup(BrickKey key, double& out) const;
  void store(BrickKey key, double e) const;

  std::size_t shard_capacity_;
  mutable std::array<Shard, kShards> shards_;
  mutable std::atomic<std::uint64_t> measured_{0};
};

}  // namespace resoct::detail
