#include "resoct/engine/request_set.hpp"

#include <algorithm>
#include <bit>
#include <new>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct {

namespace k = resoct::kernel;

RequestSet::RequestSet(std::uint32_t capacity, std::uint32_t max_probes) {
  if (capacity == 0 || capacity > (1u << 28)) {
    throw invalid_parameter("capacity", "must be 1..2^28 keys, got " + std::to_string(capacity));
  }
  if (max_probes == 0) throw invalid_parameter("max_probes", "must be at least 1");
  const std::uint32_t cap = std::bit_ceil(capacity);
  mask_ = cap - 1u;
  log2_capacity_ = std::uint32_t(std::countr_zero(cap));
  max_probes_ = std::min(max_probes, cap);
  try {
    keys_ = std::make_unique<std::atomic<std::uint32_t>[]>(cap);
    hits_ = std::make_unique<std::atomic<std::uint32_t>[]>(cap);
    filled_slots_ = std::make_unique<std::uint32_t[]>(cap);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory,
                "capacity: no host memory for a request set of " + std::to_string(cap) + " keys");
  }
  for (std::uint32_t i = 0; i < cap; ++i) {
    keys_[i].store(k::RESOCT_REQUEST_KEY_NONE, std::memory_order_relaxed);
    hits_[i].store(0, std::memory_order_relaxed);
  }
}

bool RequestSet::insert(std::uint32_t key, std::uint32_t hits) noexcept {
  if (key != k::RESOCT_REQUEST_KEY_NONE) {
    std::uint32_t i = k::resoct_request_key_hash(key, log2_capacity_);
    for (std::uint32_t probe = 0; probe < max_probes_; ++probe, i = (i + 1u) & mask_) {
      std::uint32_t cur = keys_[i].load(std::memory_order_acquire);
      if (cur == k::RESOCT_REQUEST_KEY_NONE) {
        if (keys_[i].compare_exchange_strong(cur, key, std::memory_order_acq_rel,
                                             std::memory_order_acquire)) {
          // Slots only go from free to a key during a frame, so at most `capacity` claims
          // happen and the index stays in bounds.
          filled_slots_[filled_.fetch_add(1u, std::memory_order_relaxed)] = i;
          hits_[i].fetch_add(hits, std::memory_order_relaxed);
          return true;
        }
        // Lost the race: cur now holds the winner's key, which may be ours.
      }
      if (cur == key) {
        hits_[i].fetch_add(hits, std::memory_order_relaxed);
        return true;
      }
    }
  }
  dropped_.fetch_add(1u, std::memory_order_relaxed);
  return false;
}

void RequestSet::clear() noexcept {
  const std::uint32_t n = filled_.load(std::memory_order_relaxed);
  for (std::uint32_t j = 0; j < n; ++j) {
    const std::uint32_t i = filled_slots_[j];
    keys_[i].store(k::RESOCT_REQUEST_KEY_NONE, std::memory_order_relaxed);
    hits_[i].store(0, std::memory_order_relaxed);
  }
  filled_.store(0, std::memory_order_relaxed);
  dropped_.store(0, std::memory_order_relaxed);
}

RequestBatch RequestSet::drain(const LevelFn& level_of) {
  RequestBatch batch;
  const std::uint32_t n = filled_.load(std::memory_order_acquire);
  batch.requests.reserve(n);
  for (std::uint32_t j = 0; j < n; ++j) {
    const std::uint32_t i = filled_slots_[j];
    Request r;
    r.key = keys_[i].load(std::memory_order_relaxed);
    r.hits = hits_[i].load(std::memory_order_relaxed);
    r.level = level_of ? level_of(r.key) : 0u;
    batch.requests.push_back(r);
  }
  batch.dropped = dropped();
  clear();
  std::sort(batch.requests.begin(), batch.requests.end(), [](const Request& a, const Request& b) {
    if (a.level != b.level) return a.level > b.level;
    if (a.hits != b.hits) return a.hits > b.hits;
    return a.key < b.key;
  });
  return batch;
}

RequestBatch RequestSet::drain() {
  return drain(LevelFn{});
}

glm::uvec3 coarser_brick(const BrickHierarchy& h, std::uint32_t from, const glm::uvec3& brick,
                         std::uint32_t level) {
  if (level < from || level >= h.level_count()) {
    throw invalid_parameter("level", "must be in [" + std::to_string(from) + ", " +
                                         std::to_string(h.level_count()) + "), got " +
                                         std::to_string(level));
  }
  const glm::uvec3 shift = h.level(level).factor_log2 - h.level(from).factor_log2;
  const glm::uvec3 last = h.level(level).bricks - 1u;
  return glm::min(brick >> shift, last);
}

std::vector<PageAddress> bricks_to_request(
    const BrickHierarchy& h, const PageAddress& target, RequestStrategy strategy,
    const std::function<bool(const PageAddress&)>& available) {
  if (target.level >= h.level_count()) {
    throw invalid_parameter("target.level", std::to_string(target.level) + " out of range");
  }
  std::vector<PageAddress> out{target};
  if (strategy == RequestStrategy::global) return out;
  for (std::uint32_t l = target.level + 1u; l < h.level_count(); ++l) {
    const PageAddress a{target.slot, l, coarser_brick(h, target.level, target.brick, l)};
    if (available && available(a)) break;
    out.push_back(a);
  }
  return out;
}

}  // namespace resoct
