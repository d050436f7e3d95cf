#include "io/formats/brick_error_cache.hpp"

#include <algorithm>

namespace resoct::detail {

BrickErrorCache::BrickErrorCache(std::uint64_t entries)
    : shard_capacity_(std::size_t(std::max<std::uint64_t>(1, entries / kShards))) {}

bool BrickErrorCache::lookup(BrickKey key, double& out) const {
  Shard& s = shard(key);
  const std::lock_guard<std::mutex> g(s.mutex);
  const auto it = s.entries.find(key);
  if (it == s.entries.end()) return false;
  out = it->second;
  return true;
}

void BrickErrorCache::store(BrickKey key, double e) const {
  measured_.fetch_add(1, std::memory_order_relaxed);
  Shard& s = shard(key);
  const std::lock_guard<std::mutex> g(s.mutex);
  if (s.entries.size() >= shard_capacity_) s.entries.clear();
  s.entries[key] = e;
}

}  // namespace resoct::detail
