#include "resoct/cache/host_brick_cache.hpp"

#include <algorithm>

namespace resoct {

namespace {
constexpr std::uint32_t kInitialSlots = 256;
}

HostBrickCache::HostBrickCache(std::uint64_t capacity_bytes, std::unique_ptr<EvictionPolicy> policy)
    : capacity_(capacity_bytes), policy_(std::move(policy)) {
  if (!policy_) policy_ = std::make_unique<LruPolicy>();
  entries_.resize(kInitialSlots);
  pins_.resize(kInitialSlots);
  for (std::uint32_t s = kInitialSlots; s-- > 0;) free_.push_back(s);
  policy_->reset(kInitialSlots);
}

HostBrickCache::~HostBrickCache() = default;

void HostBrickCache::distances_changed() {
  std::lock_guard lock(mutex_);
  policy_->distances_changed();
}

std::string_view HostBrickCache::policy_name() const noexcept {
  return policy_->name();
}

void HostBrickCache::set_frame(std::uint64_t frame) {
  std::lock_guard lock(mutex_);
  frame_ = frame;
}

void HostBrickCache::record_use(std::uint32_t slot) {
  ++seq_;
  entries_[slot].last_frame = frame_;
  entries_[slot].last_seq = seq_;
  pins_[slot].last_use = seq_;
}

void HostBrickCache::grow() {
  // Policies have a fixed slot count, so growth rebuilds the policy: every live entry is
  // re-inserted in its order of last use, which restores the LRU order and the Octreemizer ages.
  const auto old = std::uint32_t(entries_.size());
  const std::uint32_t next = old * 2;
  entries_.resize(next);
  pins_.resize(next);
  for (std::uint32_t s = next; s-- > old;) free_.push_back(s);
  std::vector<std::uint32_t> live;
  for (std::uint32_t s = 0; s < old; ++s) {
    if (entries_[s].brick) live.push_back(s);
  }
  std::sort(live.begin(), live.end(), [&](std::uint32_t a, std::uint32_t b) {
    return entries_[a].last_seq < entries_[b].last_seq;
  });
  policy_->reset(next);
  for (std::uint32_t s : live)
    policy_->on_insert(s, entries_[s].brick->key, entries_[s].last_frame);
}

std::uint32_t HostBrickCache::take_slot() {
  if (free_.empty()) grow();
  const std::uint32_t s = free_.back();
  free_.pop_back();
  return s;
}

void HostBrickCache::remove_slot(std::uint32_t slot) {
  Entry& e = entries_[slot];
  bytes_ -= cost(*e.brick);
  index_.erase(TimedBrickKey{e.brick->key, e.brick->timepoint});
  policy_->on_remove(slot);
  e = Entry{};
  pins_[slot] = CacheSlot{};
  free_.push_back(slot);
}

std::shared_ptr<const HostBrick> HostBrickCache::get(BrickKey key, std::uint32_t timepoint) {
  std::lock_guard lock(mutex_);
  auto it = index_.find(TimedBrickKey{key, timepoint});
  if (it == index_.end()) {
    ++stats_.misses;
    return nullptr;
  }
  ++stats_.hits;
  record_use(it->second);
  policy_->on_touch(it->second, frame_);
  return entries_[it->second].brick;
}

bool HostBrickCache::contains(BrickKey key, std::uint32_t timepoint) const {
  std::lock_guard lock(mutex_);
  return index_.count(TimedBrickKey{key, timepoint}) != 0;
}

void HostBrickCache::put(std::shared_ptr<const HostBrick> brick) {
  if (!brick) return;
  const std::uint64_t c = cost(*brick);
  std::lock_guard lock(mutex_);
  // A brick that cannot fit would evict everything and then itself; keep the cache instead.
  if (c > capacity_) return;
  const TimedBrickKey timed{brick->key, brick->timepoint};
  auto it = index_.find(timed);
  if (it != index_.end()) remove_slot(it->second);
  const std::uint32_t slot = take_slot();
  const BrickKey key = brick->key;
  entries_[slot].brick = std::move(brick);
  index_.emplace(timed, slot);
  bytes_ += c;
  record_use(slot);
  policy_->on_insert(slot, key, frame_);
  ++stats_.insertions;
  evict_to_fit();
}

void HostBrickCache::evict_to_fit() {
  if (bytes_ <= capacity_) return;
  // One policy "frame" per insertion: only the brick just inserted is pinned (it was used in
  // the current operation), so pin states cannot change during the search, as policies expect.
  policy_->begin_frame(frame_);
  const PinState pins{pins_.data(), seq_, 0};
  while (bytes_ > capacity_) {
    const std::optional<std::uint32_t> victim = policy_->victim(pins);
    if (!victim) break;  // only the new brick is left, and it fits (checked by put)
    remove_slot(*victim);
    ++stats_.evictions;
  }
}

void HostBrickCache::clear() {
  std::lock_guard lock(mutex_);
  for (std::uint32_t s = 0; s < entries_.size(); ++s) {
    if (entries_[s].brick) remove_slot(s);
  }
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
