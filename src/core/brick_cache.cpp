#include "resoct/brick_cache.hpp"

#include <string>

#include "resoct/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"

namespace resoct {

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
  if (slots > std::uint64_t(kernel::kPageMaxCacheSlot) + 1u) {
    throw invalid_parameter(
        "capacity_bytes", std::to_string(slots) + " slots exceed the 2^30 a page entry addresses");
  }
  if (!policy_) policy_ = std::make_unique<LruPolicy>();
  const auto n = std::uint32_t(slots);
  keys_.assign(n, kFreeKey);
  last_use_.assign(n, 0);
  uploaded_.assign(n, 0);
  free_.resize(n);
  // Lowest slot first: free_ is a stack.
  for (std::uint32_t i = 0; i < n; ++i) free_[i] = n - 1u - i;
  index_.reserve(n);
  policy_->reset(n);
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
  const auto it = index_.find(key.bits());
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

std::optional<BrickKey> BrickCache::key_of(std::uint32_t slot) const {
  if (slot >= keys_.size() || keys_[slot] == kFreeKey) return std::nullopt;
  return BrickKey::from_bits(keys_[slot]);
}

void BrickCache::check_resident(std::uint32_t slot) const {
  if (slot >= keys_.size() || keys_[slot] == kFreeKey) {
    throw Error(ErrorCode::out_of_range, "cache slot " + std::to_string(slot) + " is not resident");
  }
}

bool BrickCache::pinned(std::uint32_t slot) const {
  check_resident(slot);
  return pins().pinned(slot);
}

void BrickCache::touch(std::uint32_t slot) {
  check_resident(slot);
  if (last_use_[slot] == frame_) return;  // already at the MRU end for this frame
  last_use_[slot] = frame_;
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
    out.evicted = BrickKey::from_bits(keys_[*v]);
    policy_->on_remove(*v);
    index_.erase(keys_[*v]);
    --resident_;
    ++stats_.evictions;
  }
  keys_[out.slot] = key.bits();
  last_use_[out.slot] = frame_;
  uploaded_[out.slot] = frame_;
  index_.emplace(key.bits(), out.slot);
  ++resident_;
  ++stats_.insertions;
  policy_->on_insert(out.slot, key, frame_);
  return out;
}

void BrickCache::release(std::uint32_t slot) {
  if (slot >= keys_.size() || keys_[slot] == kFreeKey) return;
  policy_->on_remove(slot);
  index_.erase(keys_[slot]);
  keys_[slot] = kFreeKey;
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
