#include "resoct/engine/brick_loader.hpp"

#include <algorithm>
#include <exception>
#include <new>
#include <utility>

#include "resoct/base/error.hpp"
#include "resoct/sources/brick_error.hpp"

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
                         std::unique_ptr<EvictionPolicy> host_policy,
                         std::shared_ptr<const OctreeLayout> leaf_layout, bool measure_errors)
    : leaf_layout_(std::move(leaf_layout)),
      measure_errors_(measure_errors),
      cache_(host_cache_bytes, std::move(host_policy)) {
  if (!source) throw invalid_parameter("source", "must not be null");
  sources_ = std::make_shared<TimepointSources>(std::move(source));
  current_ = sources_->series();
  timepoint_ = current_->timepoint();
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
    release_due_retries_locked();
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
      if (prefetching_.count(TimedBrickKey{r.key, timepoint_})) {
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

std::uint32_t BrickLoader::timepoint() const {
  std::lock_guard lock(mutex_);
  return timepoint_;
}

void BrickLoader::set_timepoint(std::uint32_t t) {
  {
    std::lock_guard lock(mutex_);
    if (t == timepoint_) return;
  }
  // Opened outside the lock: opening may read metadata (or scan a small level 0).
  std::shared_ptr<const BrickSource> next = sources_->at(t);
  {
    std::lock_guard lock(mutex_);
    if (t == timepoint_) return;
    stats_.cancelled += queue_.size();
    queue_.clear();
    queued_keys_.clear();
    ready_.clear();
    adopted_.clear();
    failed_.clear();
    reported_.clear();
    retry_.clear();
    // Still running: they complete into the host cache but are never delivered.
    stale_in_flight_ += in_flight_.size();
    in_flight_.clear();
    ++generation_;
    timepoint_ = t;
    current_ = std::move(next);
    ++stats_.timepoint_switches;
  }
  idle_cv_.notify_all();
}

bool BrickLoader::known_locked(const TimedBrickKey& k) const {
  if (prefetching_.count(k) || cache_.contains(k.key, k.timepoint)) return true;
  if (k.timepoint != timepoint_) return false;
  return queued_keys_.count(k.key) || in_flight_.count(k.key) || ready_.count(k.key) ||
         failed_.count(k.key);
}

BrickLoader::Job BrickLoader::pop_locked() {
  const LoadRequest r = queue_.back();
  queue_.pop_back();
  queued_keys_.erase(r.key);
  in_flight_.insert(r.key);
  return Job{r, timepoint_, generation_, current_};
}

std::size_t BrickLoader::run_queued(std::size_t max) {
  std::size_t done = 0;
  while (done < max) {
    Job job;
    {
      std::lock_guard lock(mutex_);
      if (queue_.empty()) break;
      job = pop_locked();
    }
    load_one(job);
    ++done;
  }
  return done;
}

std::optional<TimedBrickKey> BrickLoader::pop_prefetch_locked() {
  while (!prefetch_.empty()) {
    const TimedBrickKey key = prefetch_.front();
    prefetch_.pop_front();
    // Requested, loaded or failed since it was queued: nothing left to prefetch.
    if (known_locked(key)) continue;
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
      const Job job = pop_locked();
      lock.unlock();
      load_one(job);
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
  std::vector<TimedBrickKey> timed;
  timed.reserve(keys.size());
  const std::uint32_t t = timepoint();
  for (const BrickKey key : keys) timed.push_back(TimedBrickKey{key, t});
  prefetch(std::span<const TimedBrickKey>(timed));
}

void BrickLoader::prefetch(std::span<const TimedBrickKey> keys) {
  {
    std::lock_guard lock(mutex_);
    prefetch_.clear();
    std::unordered_set<TimedBrickKey> seen;
    for (const TimedBrickKey& key : keys) {
      if (!seen.insert(key).second || known_locked(key)) continue;
      prefetch_.push_back(key);
    }
  }
  work_cv_.notify_all();
}

std::size_t BrickLoader::run_prefetch(std::size_t max) {
  std::size_t done = 0;
  while (done < max) {
    std::optional<TimedBrickKey> key;
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

std::shared_ptr<const HostBrick> BrickLoader::read_brick(const BrickSource& source, BrickKey key,
                                                         std::uint32_t t, std::string& failure,
                                                         bool& transient) {
  transient = false;
  try {
    auto b = std::make_shared<HostBrick>();
    b->key = key;
    b->timepoint = t;
    const VoxelType type = source.volume().type;
    b->voxels.resize(source.hierarchy().layout().padded_voxels() * voxel_size(type));
    source.read_brick(key, b->voxels);
    b->meta = scan_brick(b->voxels, type);
    // Measured before a constant brick's voxels go: a HOMOGENEOUS entry carries an error too.
    if (measure_errors_ && key.level() > 0 && !b->meta.all_zero()) {
      b->error = brick_error_to_float(source.brick_error(key, b->voxels));
    }
    // A constant brick needs no cache slot, so its voxels are dead weight on the host.
    if (b->meta.constant) std::vector<std::byte>().swap(b->voxels);
    cache_.put(b);
    return b;
  } catch (const std::exception& e) {
    // Any exception (also bad_alloc) marks the brick failed, and the worker thread must survive
    // it. Only a failure that may pass is retried (set_transient_retry): corrupt data would fail
    // again and block convergence.
    if (const auto* err = dynamic_cast<const Error*>(&e)) {
      transient = err->code() == ErrorCode::io || err->code() == ErrorCode::truncated ||
                  err->code() == ErrorCode::out_of_memory;
    } else {
      transient = dynamic_cast<const std::bad_alloc*>(&e) != nullptr;
    }
    const glm::uvec3 c = key.brick();
    // The timepoint is named only for a series, so that messages of other data stay as they were.
    const std::string when =
        source.timepoints() > 1 ? " timepoint " + std::to_string(t) + "," : std::string();
    failure = source.name() + ":" + when + " brick level " + std::to_string(key.level()) +
              " channel " + std::to_string(key.channel()) + " (" + std::to_string(c.x) + ", " +
              std::to_string(c.y) + ", " + std::to_string(c.z) + "): " + e.what();
    return nullptr;
  }
}

void BrickLoader::prefetch_one(const TimedBrickKey& key) {
  std::string failure;
  bool transient = false;
  std::shared_ptr<const HostBrick> result;
  try {
    const std::shared_ptr<const BrickSource> source = sources_->at(key.timepoint);
    result = read_brick(*source, key.key, key.timepoint, failure, transient);
  } catch (const std::exception& e) {
    failure = sources_->series()->name() + ": timepoint " + std::to_string(key.timepoint) + ": " +
              e.what();
  }
  // A prefetched brick requested meanwhile is delivered with its leaves' records, scanned here
  // outside the lock; an adoption that arrives after this look is delivered without them (the
  // renderer then scans on its own thread).
  std::optional<LoadedBrick> scanned;
  if (result && leaf_layout_) {
    std::optional<LoadRequest> wanted;
    {
      std::lock_guard lock(mutex_);
      const auto a = key.timepoint == timepoint_ ? adopted_.find(key.key) : adopted_.end();
      if (a != adopted_.end()) wanted = a->second;
    }
    if (wanted) scanned = deliver(result, *wanted);
  }
  {
    std::lock_guard lock(mutex_);
    prefetching_.erase(key);
    // Adoptions belong to the current timepoint (set_timepoint() clears them).
    const auto adopted = key.timepoint == timepoint_ ? adopted_.find(key.key) : adopted_.end();
    if (result) {
      if (adopted != adopted_.end()) {
        const LoadRequest& r = adopted->second;
        LoadedBrick d = scanned ? std::move(*scanned) : LoadedBrick{result};
        d.hits = r.hits;
        d.since = r.since;
        d.rank = r.rank;
        ready_[key.key] = std::move(d);
        ++stats_.prefetch_hits;
      } else {
        prefetched_.insert(key);
      }
      ++stats_.prefetched;
      if (key.timepoint == timepoint_) retry_.erase(key.key);
    } else if (key.timepoint == timepoint_) {
      fail_locked(key.key, std::move(failure), transient);
    }
    if (adopted != adopted_.end()) adopted_.erase(adopted);
  }
  idle_cv_.notify_all();
}

LoadedBrick BrickLoader::deliver(std::shared_ptr<const HostBrick> brick,
                                 const LoadRequest& r) const {
  LoadedBrick out{std::move(brick), r.hits, r.since, r.rank};
  const HostBrick& b = *out.brick;
  if (leaf_layout_ && b.key.level() == 0 && !b.meta.constant) {
    // The series' range, as the renderer gives the octree slot (ResidencyOctree::remap_slot).
    const BrickSource& series = *sources_->series();
    try {
      out.leaves = scan_leaves(*leaf_layout_, series.hierarchy(),
                               series.volume().range(b.key.channel()), b.key.brick(), b.voxels);
      out.leaf_size = leaf_layout_->leaf_size();
    } catch (const std::exception&) {
      // A worker thread must survive anything (also bad_alloc): the brick goes out without the
      // records, and the renderer scans it on its own thread (where an error is reported).
      out.leaves.clear();
      out.leaf_size = glm::uvec3(0);
    }
  }
  return out;
}

void BrickLoader::load_one(const Job& job) {
  const LoadRequest& r = job.request;
  std::shared_ptr<const HostBrick> result = cache_.get(r.key, job.timepoint);
  const bool from_cache = result != nullptr;
  std::string failure;
  bool transient = false;
  if (!result) result = read_brick(*job.source, r.key, job.timepoint, failure, transient);
  // The leaves' records are computed here, outside the lock, also for a host cache hit; not for a
  // job a timepoint switch has already made stale (it is dropped below).
  bool stale = false;
  {
    std::lock_guard lock(mutex_);
    stale = job.generation != generation_;
  }
  std::optional<LoadedBrick> loaded;
  if (result && !stale) loaded = deliver(result, r);
  {
    std::lock_guard lock(mutex_);
    if (job.generation != generation_) {
      // The timepoint changed while this brick loaded: delivering it would show voxels of
      // the old timepoint in a frame of the new one.
      --stale_in_flight_;
      ++stats_.stale_dropped;
      idle_cv_.notify_all();
      return;
    }
    in_flight_.erase(r.key);
    // Counted once: a prefetched brick served from the cache, or read again after its eviction.
    if (prefetched_.erase(TimedBrickKey{r.key, job.timepoint}) && from_cache) {
      ++stats_.prefetch_hits;
    }
    if (loaded) {
      ready_[r.key] = std::move(*loaded);
      ++(from_cache ? stats_.host_hits : stats_.loads);
      retry_.erase(r.key);
    } else {
      fail_locked(r.key, std::move(failure), transient);
    }
  }
  idle_cv_.notify_all();
}

void BrickLoader::fail_locked(BrickKey key, std::string failure, bool transient) {
  failed_.insert(key);
  if (transient && retry_first_.count() > 0) {
    Retry& r = retry_[key];
    // first, 2 first, 4 first, ... 32 first: a server that stays down is asked rarely.
    r.due = std::chrono::steady_clock::now() + retry_first_ * (1u << std::min(r.attempts, 5u));
    ++r.attempts;
  } else {
    retry_.erase(key);
  }
  if (reported_.insert(key).second) {
    new_failures_.push_back(LoadFailure{key, std::move(failure)});
    ++stats_.failures;
  }
}

void BrickLoader::release_due_retries_locked() {
  if (retry_.empty()) return;
  const auto now = std::chrono::steady_clock::now();
  for (const auto& [key, r] : retry_) {
    if (r.due <= now && failed_.erase(key)) ++stats_.retries;
  }
}

void BrickLoader::set_transient_retry(std::chrono::milliseconds first) {
  if (first.count() < 0 || first > std::chrono::hours(1)) {
    throw invalid_parameter("retry_after_ms", "must be in [0, 3600000]");
  }
  std::lock_guard lock(mutex_);
  retry_first_ = first;
  if (first.count() == 0) retry_.clear();
}

std::size_t BrickLoader::retries_pending() const {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& [key, r] : retry_) n += failed_.count(key);
  return n;
}

void BrickLoader::wait_idle() {
  std::unique_lock lock(mutex_);
  if (workers_.empty()) return;  // nothing runs in the background
  idle_cv_.wait(lock, [this] {
    return queue_.empty() && in_flight_.empty() && prefetch_.empty() && prefetching_.empty() &&
           stale_in_flight_ == 0;
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
  if (failed_.count(key) == 0) return false;
  const auto r = retry_.find(key);
  return r == retry_.end() || std::chrono::steady_clock::now() < r->second.due;
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
