#include "resoct/cache/eviction_policy.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

// ---- LRU ----------------------------------------------------------------------------------------

void LruPolicy::reset(std::uint32_t slot_count) {
  links_.assign(slot_count, Link{});
  head_ = tail_ = cursor_ = kNone;
}

void LruPolicy::begin_frame(std::uint64_t /*frame*/) {
  cursor_ = head_;
}

void LruPolicy::unlink(std::uint32_t s) {
  Link& link = links_[s];
  if (cursor_ == s) cursor_ = link.next;
  (link.prev == kNone ? head_ : links_[link.prev].next) = link.next;
  (link.next == kNone ? tail_ : links_[link.next].prev) = link.prev;
  link = Link{};
}

void LruPolicy::append(std::uint32_t s) {
  links_[s] = Link{tail_, kNone};
  (tail_ == kNone ? head_ : links_[tail_].next) = s;
  tail_ = s;
  // A cursor that ran off the end resumes at the new slot (which is pinned: used this frame).
  if (cursor_ == kNone) cursor_ = s;
}

void LruPolicy::on_insert(std::uint32_t slot, BrickKey /*key*/, std::uint64_t /*frame*/) {
  append(slot);
}

void LruPolicy::on_touch(std::uint32_t slot, std::uint64_t /*frame*/) {
  if (slot == tail_) return;
  unlink(slot);
  append(slot);
}

void LruPolicy::on_remove(std::uint32_t slot) {
  unlink(slot);
}

std::optional<std::uint32_t> LruPolicy::victim(const PinState& pins) {
  while (cursor_ != kNone) {
    const std::uint32_t s = cursor_;
    // Slots used this frame sit at the tail, behind every other slot: nothing further is free.
    if (pins.last_use(s) == pins.frame) return std::nullopt;
    if (!pins.pinned(s)) return s;
    cursor_ = links_[s].next;  // pinned by ttl for the rest of this frame
  }
  return std::nullopt;
}

double brick_camera_distance(const BrickHierarchy& h, BrickKey key, const glm::dvec3& camera) {
  if (key.level() >= h.level_count() || !h.contains(BrickKey(key.level(), 0, key.brick()))) {
    throw Error(ErrorCode::out_of_range, "brick key outside the hierarchy");
  }
  const Box3 box = h.level0_box(key.level(), key.brick());
  const glm::dvec3 centre = 0.5 * glm::dvec3(box.lo + box.hi) * h.volume().spacing;
  return glm::length(centre - camera);
}

// ---- Octreemizer --------------------------------------------------------------------------------

OctreemizerPolicy::OctreemizerPolicy(std::uint32_t level_count, OctreemizerWeights weights,
                                     DistanceFn distance)
    : level_count_(level_count), w_(weights), distance_fn_(std::move(distance)) {
  if (level_count == 0 || level_count > BrickKey::kMaxLevel + 1u) {
    throw invalid_parameter("level_count", "must be 1..32, got " + std::to_string(level_count));
  }
  const auto check = [](double v, const char* name) {
    if (!std::isfinite(v) || v < 0.0) {
      throw invalid_parameter(name, "must be a finite non-negative weight");
    }
  };
  check(w_.ka, "ka");
  check(w_.kl, "kl");
  check(w_.kd, "kd");
}

void OctreemizerPolicy::reset(std::uint32_t slot_count) {
  entries_.assign(slot_count, Entry{});
  pos_.assign(slot_count, kAbsent);
  heap_.clear();
  heap_.reserve(slot_count);
  parked_.clear();
  stale_ = false;
}

double OctreemizerPolicy::rank(std::uint32_t s) const {
  const Entry& e = entries_[s];
  const double depth = double(level_count_ - 1u) - double(e.key.level());
  return w_.kl * depth + w_.kd * e.distance - w_.ka * double(e.last_use);
}

double OctreemizerPolicy::priority(std::uint32_t slot, std::uint64_t frame) const {
  if (slot >= pos_.size() || pos_[slot] == kAbsent) {
    throw Error(ErrorCode::out_of_range, "slot " + std::to_string(slot) + " is not resident");
  }
  const Entry& e = entries_[slot];
  const double depth = double(level_count_ - 1u) - double(e.key.level());
  return w_.ka * double(frame - e.last_use) + w_.kl * depth + w_.kd * e.distance;
}

void OctreemizerPolicy::place(std::size_t i, const HeapItem& item) {
  heap_[i] = item;
  pos_[item.slot] = std::uint32_t(i);
}

void OctreemizerPolicy::sift_up(std::size_t i) {
  const HeapItem item = heap_[i];
  while (i > 0) {
    const std::size_t parent = (i - 1) / 2;
    if (heap_[parent].rank >= item.rank) break;
    place(i, heap_[parent]);
    i = parent;
  }
  place(i, item);
}

void OctreemizerPolicy::sift_down(std::size_t i) {
  const HeapItem item = heap_[i];
  const std::size_t n = heap_.size();
  for (;;) {
    std::size_t c = 2 * i + 1;
    if (c >= n) break;
    if (c + 1 < n && heap_[c + 1].rank > heap_[c].rank) ++c;
    if (heap_[c].rank <= item.rank) break;
    place(i, heap_[c]);
    i = c;
  }
  place(i, item);
}

void OctreemizerPolicy::heap_push(std::uint32_t slot) {
  heap_.push_back(HeapItem{rank(slot), slot});
  pos_[slot] = std::uint32_t(heap_.size() - 1);
  sift_up(heap_.size() - 1);
}

void OctreemizerPolicy::heap_erase(std::uint32_t slot) {
  const std::size_t i = pos_[slot];
  const HeapItem last = heap_.back();
  heap_.pop_back();
  pos_[slot] = kAbsent;
  if (last.slot == slot) return;
  place(i, last);
  sift_up(i);
  sift_down(pos_[last.slot]);
}

void OctreemizerPolicy::heap_fix(std::uint32_t slot) {
  if (pos_[slot] >= kParked) return;  // parked or free: ordered when it returns to the heap
  const std::size_t i = pos_[slot];
  const double old = heap_[i].rank;
  heap_[i].rank = rank(slot);
  if (heap_[i].rank > old) {
    sift_up(i);
  } else {
    sift_down(i);
  }
}

void OctreemizerPolicy::begin_frame(std::uint64_t /*frame*/) {
  for (std::uint32_t s : parked_) {
    if (pos_[s] == kParked) heap_push(s);
  }
  parked_.clear();
}

void OctreemizerPolicy::on_insert(std::uint32_t slot, BrickKey key, std::uint64_t frame) {
  Entry& e = entries_[slot];
  e.key = key;
  e.last_use = frame;
  e.distance = distance_fn_ ? distance_fn_(key) : 0.0;
  heap_push(slot);
}

void OctreemizerPolicy::on_touch(std::uint32_t slot, std::uint64_t frame) {
  Entry& e = entries_[slot];
  e.last_use = frame;
  if (distance_fn_) e.distance = distance_fn_(e.key);
  heap_fix(slot);
}

void OctreemizerPolicy::on_remove(std::uint32_t slot) {
  if (pos_[slot] == kParked) {
    pos_[slot] = kAbsent;  // its stale parked_ record is skipped at begin_frame
  } else if (pos_[slot] != kAbsent) {
    heap_erase(slot);
  }
}

void OctreemizerPolicy::set_distance(std::uint32_t slot, double distance) {
  if (slot >= pos_.size() || pos_[slot] == kAbsent) return;
  if (!std::isfinite(distance)) throw invalid_parameter("distance", "must be finite");
  entries_[slot].distance = distance;
  heap_fix(slot);
}

void OctreemizerPolicy::refresh_distances() {
  stale_ = false;
  if (!distance_fn_) return;
  for (std::uint32_t s = 0; s < pos_.size(); ++s) {
    if (pos_[s] != kAbsent) entries_[s].distance = distance_fn_(entries_[s].key);
  }
  // Every rank may have changed: re-rank in place and heapify bottom-up (O(n)); parked slots are
  // ranked when they return at the next begin_frame().
  for (HeapItem& item : heap_) item.rank = rank(item.slot);
  for (std::size_t i = heap_.size() / 2; i-- > 0;) sift_down(i);
}

std::optional<std::uint32_t> OctreemizerPolicy::victim(const PinState& pins) {
  if (stale_) refresh_distances();
  while (!heap_.empty()) {
    const std::uint32_t s = heap_.front().slot;
    if (!pins.pinned(s)) return s;
    // Pinned for the rest of this frame: park it so later searches do not meet it again.
    heap_erase(s);
    pos_[s] = kParked;
    parked_.push_back(s);
  }
  return std::nullopt;
}

}  // namespace resoct
