#include "resoct/brick_loader.hpp"

#include <algorithm>
#include <exception>
#include <utility>

#include "resoct/error.hpp"

namespace resoct {

bool load_before(const LoadRequest& a, const LoadRequest& b) noexcept {
  if (a.key.level() != b.key.level()) return a.key.level() > b.key.level();
  if (a.rank != b.rank) return a.rank < b.rank;
  if (a.since != b.since) return a.since < b.since;
  if (a.hits != b.hits) return a.hits > b.hits;
  return a.key < b.key;
}

BrickLoader::BrickLoader(std::shared_ptr<const BrickSource> source, std::uint32_t threads,
                         std::uint64_t host_cache_bytes,
                         std::unique_ptr<EvictionPolicy> host_policy)
    : source_(std::move(source)), cache_(host_cache_bytes, std::move(host_policy)) {
  if (!source_) throw invalid_parameter("source", "must not be null");
  if (threads > 1024) throw invalid_parameter("threads", "must be at most 1024");
  workers_.reserve(threads);
  for (std::uint32_t i = 0; i < threads; ++i) workers_.emplace_back([this] { worker_main(); });
}

BrickLoader::~BrickLoader() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    queue_.clear();
    queued_keys_.clear();
    prefetch_.clear();
  }
  work_cv_.notify_all();
  for (auto& t : workers_) t.join();
}

void BrickLoader::request(std::span<const LoadRequest> wanted) {
  {
    std::lock_guard lock(mutex_);
    std::unordered_set<BrickKey> next_keys;
    std::vector<LoadRequest> next;
    std::unordered_map<BrickKey, LoadRequest> adopted;
    next.reserve(wanted.size());
    for (const LoadRequest& r : wanted) {
      if (in_flight_.count(r.key) || ready_.count(r.key) || failed_.count(r.key) ||
          adopted.count(r.key) || !next_keys.insert(r.key).second) {
        ++stats_.duplicates;
        continue;
      }
      if (prefetching_.count(r.key)) {
        next_keys.erase(r.key);
        adopted.emplace(r.key, r);
        continue;
      }
      next.push_back(r);
    }
    adopted_ = std::move(adopted);
    for (const LoadRequest& r : queue_) {
      if (!next_keys.count(r.key)) ++stats_.cancelled;
    }
    // Sorted worst first so that the best request is popped from the back in O(1).
    std::sort(next.begin(), next.end(),
              [](const LoadRequest& a, const LoadRequest& b) { return load_before(b, a); });
    queue_ = std::move(next);
    queued_keys_ = std::move(next_keys);
  }
  work_cv_.notify_all();
  idle_cv_.notify_all();
}

LoadRequest BrickLoader::pop_locked() {
  const LoadRequest r = queue_.back();
  queue_.pop_back();
  queued_keys_.erase(r.key);
  in_flight_.insert(r.key);
  return r;
}

std::size_t BrickLoader::run_queued(std::size_t max) {
  std::size_t done = 0;
  while (done < max) {
    LoadRequest r;
    {
      std::lock_guard lock(mutex_);
      if (queue_.empty()) break;
      r = pop_locked();
    }
    load_one(r);
    ++done;
  }
  return done;
}

std::optional<BrickKey> BrickLoader::pop_prefetch_locked() {
  while (!prefetch_.empty()) {
    const BrickKey key = prefetch_.front();
    prefetch_.pop_front();
    // Requested, loaded or failed since it was queued: nothing left to prefetch.
    if (queued_keys_.count(key) || in_flight_.count(key) || ready_.count(key) ||
        failed_.count(key) || prefetching_.count(key) || cache_.contains(key)) {
      continue;
    }
    prefetching_.insert(key);
    return key;
  }
  return std::nullopt;
}

void BrickLoader::worker_main() {
  std::unique_lock lock(mutex_);
  for (;;) {
    work_cv_.wait(lock, [this] { return stop_ || !queue_.empty() || !prefetch_.empty(); });
    if (stop_) return;
    if (!queue_.empty()) {
      const LoadRequest r = pop_locked();
      lock.unlock();
      load_one(r);
      lock.lock();
      continue;
    }
    // Only when no request waits: prefetches never delay what the renderer asked for.
    if (const auto key = pop_prefetch_locked()) {
      lock.unlock();
      prefetch_one(*key);
      lock.lock();
    }
  }
}

void BrickLoader::prefetch(std::span<const BrickKey> keys) {
  {
    std::lock_guard lock(mutex_);
    prefetch_.clear();
    std::unordered_set<BrickKey> seen;
    for (const BrickKey key : keys) {
      if (!seen.insert(key).second || queued_keys_.count(key) || in_flight_.count(key) ||
          ready_.count(key) || failed_.count(key) || prefetching_.count(key) ||
          cache_.contains(key)) {
        continue;
      }
      prefetch_.push_back(key);
    }
  }
  work_cv_.notify_all();
}

std::size_t BrickLoader::run_prefetch(std::size_t max) {
  std::size_t done = 0;
  while (done < max) {
    std::optional<BrickKey> key;
    {
      std::lock_guard lock(mutex_);
      key = pop_prefetch_locked();
    }
    if (!key) break;
    prefetch_one(*key);
    ++done;
  }
  return done;
}

std::size_t BrickLoader::prefetch_queued() const {
  std::lock_guard lock(mutex_);
  return prefetch_.size();
}

std::shared_ptr<const HostBrick> BrickLoader::read_brick(BrickKey key, std::string& failure) {
  try {
    auto b = std::make_shared<HostBrick>();
    b->key = key;
    const VoxelType type = source_->volume().type;
    b->voxels.resize(source_->hierarchy().layout().padded_voxels() * voxel_size(type));
    source_->read_brick(key, b->voxels);
    b->meta = scan_brick(b->voxels, type);
    // A constant brick needs no cache slot, so its voxels are dead weight on the host.
    if (b->meta.constant) std::vector<std::byte>().swap(b->voxels);
    cache_.put(b);
    return b;
  } catch (const std::exception& e) {
    // Any exception (also bad_alloc) marks the brick failed: retrying would fail again and
    // block convergence, and the worker thread must survive it.
    const glm::uvec3 c = key.brick();
    failure = source_->name() + ": brick level " + std::to_string(key.level()) + " channel " +
              std::to_string(key.channel()) + " (" + std::to_string(c.x) + ", " +
              std::to_string(c.y) + ", " + std::to_string(c.z) + "): " + e.what();
    return nullptr;
  }
}

void BrickLoader::prefetch_one(BrickKey key) {
  std::string failure;
  std::shared_ptr<const HostBrick> result = read_brick(key, failure);
  {
    std::lock_guard lock(mutex_);
    prefetching_.erase(key);
    const auto adopted = adopted_.find(key);
    if (result) {
      if (adopted != adopted_.end()) {
        const LoadRequest& r = adopted->second;
        ready_[key] = LoadedBrick{result, r.hits, r.since, r.rank};
        ++stats_.prefetch_hits;
      } else {
        prefetched_.insert(key);
      }
      ++stats_.prefetched;
    } else if (failed_.insert(key).second) {
      new_failures_.push_back(LoadFailure{key, std::move(failure)});
      ++stats_.failures;
    }
    if (adopted != adopted_.end()) adopted_.erase(adopted);
  }
  idle_cv_.notify_all();
}

void BrickLoader::load_one(const LoadRequest& r) {
  std::shared_ptr<const HostBrick> result = cache_.get(r.key);
  const bool from_cache = result != nullptr;
  std::string failure;
  if (!result) result = read_brick(r.key, failure);
  {
    std::lock_guard lock(mutex_);
    in_flight_.erase(r.key);
    // Counted once: a prefetched brick served from the cache, or read again after its eviction.
    if (prefetched_.erase(r.key) && from_cache) ++stats_.prefetch_hits;
    if (result) {
      ready_[r.key] = LoadedBrick{result, r.hits, r.since, r.rank};
      ++(from_cache ? stats_.host_hits : stats_.loads);
    } else if (failed_.insert(r.key).second) {
      new_failures_.push_back(LoadFailure{r.key, std::move(failure)});
      ++stats_.failures;
    }
  }
  idle_cv_.notify_all();
}

void BrickLoader::wait_idle() {
  std::unique_lock lock(mutex_);
  if (workers_.empty()) return;  // nothing runs in the background
  idle_cv_.wait(lock, [this] {
    return queue_.empty() && in_flight_.empty() && prefetch_.empty() && prefetching_.empty();
  });
}

std::vector<LoadedBrick> BrickLoader::take_ready() {
  std::vector<LoadedBrick> out;
  {
    std::lock_guard lock(mutex_);
    out.reserve(ready_.size());
    for (auto& [key, b] : ready_) out.push_back(std::move(b));
    ready_.clear();
  }
  std::sort(out.begin(), out.end(), [](const LoadedBrick& a, const LoadedBrick& b) {
    return load_before(a.request(), b.request());
  });
  return out;
}

std::vector<LoadFailure> BrickLoader::take_failures() {
  std::lock_guard lock(mutex_);
  return std::exchange(new_failures_, {});
}

bool BrickLoader::has_failed(BrickKey key) const {
  std::lock_guard lock(mutex_);
  return failed_.count(key) != 0;
}

std::size_t BrickLoader::queued() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

std::size_t BrickLoader::in_flight() const {
  std::lock_guard lock(mutex_);
  return in_flight_.size() + adopted_.size();
}

std::size_t BrickLoader::ready() const {
  std::lock_guard lock(mutex_);
  return ready_.size();
}

bool BrickLoader::idle() const {
  std::lock_guard lock(mutex_);
  return queue_.empty() && in_flight_.empty() && ready_.empty() && adopted_.empty();
}

BrickLoaderStats BrickLoader::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace resoct
