#include "resoct/engine/brick_cache.hpp"

#include <new>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"

namespace resoct {

namespace detail {

void KeySlotIndex::reset(std::uint32_t max_entries) {
  std::size_t n = 2;
  while (n < 2 * std::size_t(max_entries)) n *= 2;
  cells_.assign(n, Cell{});
  mask_ = n - 1;
}

std::size_t KeySlotIndex::home(std::uint64_t key) const noexcept {
  return std::hash<BrickKey>{}(BrickKey::from_bits(key)) & mask_;
}

std::optional<std::uint32_t> KeySlotIndex::find(std::uint64_t key) const noexcept {
  for (std::size_t i = home(key);; i = (i + 1) & mask_) {
    if (cells_[i].key == key) return cells_[i].slot;
    if (cells_[i].key == kEmpty) return std::nullopt;
  }
}

void KeySlotIndex::insert(std::uint64_t key, std::uint32_t slot) noexcept {
  std::size_t i = home(key);
  while (cells_[i].key != kEmpty) i = (i + 1) & mask_;
  cells_[i] = Cell{key, slot};
}

void KeySlotIndex::erase(std::uint64_t key) noexcept {
  std::size_t i = home(key);
  while (cells_[i].key != key) {
    if (cells_[i].key == kEmpty) return;
    i = (i + 1) & mask_;
  }
  // Backward shift: pull later members of the probe run into the hole so that no tombstones are
  // needed and probe runs stay short.
  for (std::size_t j = (i + 1) & mask_; cells_[j].key != kEmpty; j = (j + 1) & mask_) {
    const std::size_t h = home(cells_[j].key);
    if (((j - h) & mask_) >= ((j - i) & mask_)) {
      cells_[i] = cells_[j];
      i = j;
    }
  }
  cells_[i] = Cell{};
}

}  // namespace detail

BrickCache::BrickCache(const BrickLayout& layout, VoxelType type, std::uint64_t capacity_bytes,
                       std::uint32_t ttl, std::unique_ptr<EvictionPolicy> policy)
    : type_(type), ttl_(ttl), policy_(std::move(policy)) {
  layout.validate();
  slot_bytes_ = layout.padded_voxels() * voxel_size(type);
  if (capacity_bytes == 0) throw invalid_parameter("capacity_bytes", "must be positive");
  if (capacity_bytes < slot_bytes_) {
    throw invalid_parameter("capacity_bytes", std::to_string(capacity_bytes) +
                                                  " bytes hold no brick of " +
                                                  std::to_string(slot_bytes_) + " bytes");
  }
  const std::uint64_t slots = capacity_bytes / slot_bytes_;
  if (slots > std::uint64_t(kernel::RESOCT_PAGE_MAX_CACHE_SLOT) + 1u) {
    throw invalid_parameter(
        "capacity_bytes", std::to_string(slots) + " slots exceed the 2^26 a page entry addresses");
  }
  if (!policy_) policy_ = std::make_unique<LruPolicy>();
  const auto n = std::uint32_t(slots);
  try {
    slots_.assign(n, CacheSlot{kFreeKey, 0, 0});
    free_.resize(n);
    index_.reset(n);
    policy_->reset(n);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory, "capacity_bytes: no host memory for the bookkeeping of " +
                                              std::to_string(n) + " cache slots");
  }
  // Lowest slot first: free_ is a stack.
  for (std::uint32_t i = 0; i < n; ++i) free_[i] = n - 1u - i;
  policy_->begin_frame(frame_);
}

void BrickCache::begin_frame(std::uint64_t frame) {
  if (started_ && frame <= frame_) {
    throw invalid_parameter("frame", "frame " + std::to_string(frame) + " does not follow frame " +
                                         std::to_string(frame_));
  }
  started_ = true;
  frame_ = frame;
  policy_->begin_frame(frame);
}

std::optional<std::uint32_t> BrickCache::find(BrickKey key) const {
  return index_.find(key.bits());
}

std::optional<BrickKey> BrickCache::key_of(std::uint32_t slot) const {
  if (slot >= slots_.size() || slots_[slot].key_bits == kFreeKey) return std::nullopt;
  return BrickKey::from_bits(slots_[slot].key_bits);
}

void BrickCache::check_resident(std::uint32_t slot) const {
  if (slot >= slots_.size() || slots_[slot].key_bits == kFreeKey) {
    throw Error(ErrorCode::out_of_range, "cache slot " + std::to_string(slot) + " is not resident");
  }
}

bool BrickCache::pinned(std::uint32_t slot) const {
  check_resident(slot);
  return pins().pinned(slot);
}

void BrickCache::touch(std::uint32_t slot) {
  check_resident(slot);
  CacheSlot& s = slots_[slot];
  if (s.last_use == frame_) return;  // already used this frame: its place is final
  s.last_use = frame_;
  policy_->on_touch(slot, frame_);
}

std::optional<CacheInsertion> BrickCache::insert(BrickKey key) {
  if (key.bits() == kFreeKey) throw invalid_parameter("key", "the all-ones brick key is reserved");
  if (const auto hit = find(key)) {
    touch(*hit);
    return CacheInsertion{*hit, std::nullopt};
  }
  CacheInsertion out;
  if (!free_.empty()) {
    out.slot = free_.back();
    free_.pop_back();
  } else {
    const std::optional<std::uint32_t> v = policy_->victim(pins());
    if (!v) {
      ++stats_.allocation_failures;
      return std::nullopt;
    }
    out.slot = *v;
    out.evicted = BrickKey::from_bits(slots_[*v].key_bits);
    policy_->on_remove(*v);
    index_.erase(slots_[*v].key_bits);
    --resident_;
    ++stats_.evictions;
  }
  slots_[out.slot] = CacheSlot{key.bits(), frame_, frame_};
  index_.insert(key.bits(), out.slot);
  ++resident_;
  ++stats_.insertions;
  policy_->on_insert(out.slot, key, frame_);
  return out;
}

void BrickCache::release(std::uint32_t slot) {
  if (slot >= slots_.size() || slots_[slot].key_bits == kFreeKey) return;
  policy_->on_remove(slot);
  index_.erase(slots_[slot].key_bits);
  slots_[slot].key_bits = kFreeKey;
  free_.push_back(slot);
  --resident_;
  ++stats_.releases;
}

UploadPlan plan_uploads(std::span<const UploadCandidate> in_priority_order,
                        const UploadBudget& budget) {
  UploadPlan plan;
  std::size_t i = 0;
  for (; i < in_priority_order.size(); ++i) {
    const UploadCandidate& c = in_priority_order[i];
    const bool bricks_ok = plan.admitted.size() < budget.max_bricks;
    const bool bytes_ok = c.bytes <= budget.max_bytes - plan.admitted_bytes;  // no overflow
    if (!bricks_ok || !bytes_ok) break;
    plan.admitted.push_back(c);
    plan.admitted_bytes += c.bytes;
  }
  plan.deferred.assign(in_priority_order.begin() + std::ptrdiff_t(i), in_priority_order.end());
  return plan;
}

}  // namespace resoct
