#include "resoct/host_brick_cache.hpp"

namespace resoct {

HostBrickCache::HostBrickCache(std::uint64_t capacity_bytes) : capacity_(capacity_bytes) {}

std::shared_ptr<const HostBrick> HostBrickCache::get(BrickKey key) {
  std::lock_guard lock(mutex_);
  auto it = index_.find(key);
  if (it == index_.end()) {
    ++stats_.misses;
    return nullptr;
  }
  ++stats_.hits;
  order_.splice(order_.begin(), order_, it->second);
  return *it->second;
}

bool HostBrickCache::contains(BrickKey key) const {
  std::lock_guard lock(mutex_);
  return index_.count(key) != 0;
}

void HostBrickCache::put(std::shared_ptr<const HostBrick> brick) {
  if (!brick) return;
  const std::uint64_t c = cost(*brick);
  std::lock_guard lock(mutex_);
  // A brick that cannot fit would evict everything and then itself; keep the cache instead.
  if (c > capacity_) return;
  auto it = index_.find(brick->key);
  if (it != index_.end()) {
    bytes_ -= cost(**it->second);
    order_.erase(it->second);
    index_.erase(it);
  }
  order_.push_front(std::move(brick));
  index_.emplace(order_.front()->key, order_.begin());
  bytes_ += c;
  ++stats_.insertions;
  evict_to_fit();
}

void HostBrickCache::evict_to_fit() {
  while (bytes_ > capacity_ && !order_.empty()) {
    const auto& victim = order_.back();
    bytes_ -= cost(*victim);
    index_.erase(victim->key);
    order_.pop_back();
    ++stats_.evictions;
  }
}

void HostBrickCache::clear() {
  std::lock_guard lock(mutex_);
  order_.clear();
  index_.clear();
  bytes_ = 0;
}

std::uint64_t HostBrickCache::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

std::size_t HostBrickCache::size() const {
  std::lock_guard lock(mutex_);
  return index_.size();
}

HostBrickCacheStats HostBrickCache::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace resoct
