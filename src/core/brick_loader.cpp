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
                         std::uint64_t host_cache_bytes)
    : source_(std::move(source)), cache_(host_cache_bytes) {
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
  }
  work_cv_.notify_all();
  for (auto& t : workers_) t.join();
}

void BrickLoader::request(std::span<const LoadRequest> wanted) {
  {
    std::lock_guard lock(mutex_);
    std::unordered_set<BrickKey> next_keys;
    std::vector<LoadRequest> next;
    next.reserve(wanted.size());
    for (const LoadRequest& r : wanted) {
      if (in_flight_.count(r.key) || ready_.count(r.key) || failed_.count(r.key) ||
          !next_keys.insert(r.key).second) {
        ++stats_.duplicates;
        continue;
      }
      next.push_back(r);
    }
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

void BrickLoader::worker_main() {
  std::unique_lock lock(mutex_);
  for (;;) {
    work_cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    const LoadRequest r = pop_locked();
    lock.unlock();
    load_one(r);
    lock.lock();
  }
}

void BrickLoader::load_one(const LoadRequest& r) {
  std::shared_ptr<const HostBrick> result = cache_.get(r.key);
  const bool from_cache = result != nullptr;
  std::string failure;
  if (!result) {
    try {
      auto b = std::make_shared<HostBrick>();
      b->key = r.key;
      const VoxelType type = source_->volume().type;
      b->voxels.resize(source_->hierarchy().layout().padded_voxels() * voxel_size(type));
      source_->read_brick(r.key, b->voxels);
      b->meta = scan_brick(b->voxels, type);
      // A constant brick needs no cache slot, so its voxels are dead weight on the host.
      if (b->meta.constant) std::vector<std::byte>().swap(b->voxels);
      result = b;
      cache_.put(result);
    } catch (const std::exception& e) {
      // Any exception (also bad_alloc) marks the brick failed: retrying would fail again and
      // block convergence, and the worker thread must survive it.
      const glm::uvec3 c = r.key.brick();
      failure = source_->name() + ": brick level " + std::to_string(r.key.level()) + " channel " +
                std::to_string(r.key.channel()) + " (" + std::to_string(c.x) + ", " +
                std::to_string(c.y) + ", " + std::to_string(c.z) + "): " + e.what();
    }
  }
  {
    std::lock_guard lock(mutex_);
    in_flight_.erase(r.key);
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
  idle_cv_.wait(lock, [this] { return queue_.empty() && in_flight_.empty(); });
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
  return in_flight_.size();
}

std::size_t BrickLoader::ready() const {
  std::lock_guard lock(mutex_);
  return ready_.size();
}

bool BrickLoader::idle() const {
  std::lock_guard lock(mutex_);
  return queue_.empty() && in_flight_.empty() && ready_.empty();
}

BrickLoaderStats BrickLoader::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace resoct
