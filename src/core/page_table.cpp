#include "resoct/page_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <string>

#include "resoct/error.hpp"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct {

namespace k = resoct::kernel;

PageTable::PageTable(const BrickHierarchy& hierarchy, std::uint32_t slots)
    : hierarchy_(hierarchy), slots_(slots), levels_(hierarchy.level_count()) {
  if (slots == 0) throw invalid_parameter("slots", "at least one visible channel slot is needed");
  if (std::uint64_t(slots) * levels_ > k::RESOCT_REQUEST_MAX_TABLES) {
    throw invalid_parameter(
        "slots", "too many page tables for 32-bit device keys: " + std::to_string(slots) +
                     " slots x " + std::to_string(levels_) + " levels exceeds " +
                     std::to_string(k::RESOCT_REQUEST_MAX_TABLES) + "; use fewer visible slots");
  }
  for (std::uint32_t l = 0; l < levels_; ++l) {
    if (hierarchy.level(l).brick_count >= k::RESOCT_REQUEST_MAX_BRICKS_PER_TABLE) {
      throw invalid_parameter("brick_size",
                              "too many bricks for 32-bit device keys: level " + std::to_string(l) +
                                  " has " + std::to_string(hierarchy.level(l).brick_count) +
                                  " bricks, at most " +
                                  std::to_string(k::RESOCT_REQUEST_MAX_BRICKS_PER_TABLE - 1u) +
                                  " fit; use bigger bricks or fewer visible slots");
    }
  }
  const std::uint64_t total = std::uint64_t(slots) * hierarchy.bricks_per_channel();
  if (total >= std::numeric_limits<std::uint32_t>::max()) {
    throw invalid_parameter("slots", "page table would need " + std::to_string(total) +
                                         " entries, more than 32-bit indices address; use bigger "
                                         "bricks or fewer visible slots");
  }
  for (std::uint32_t l = 0; l < levels_; ++l) {
    const LevelInfo& li = hierarchy.level(l);
    LevelScale ls;
    ls.scale = hierarchy.level_voxel_position(l, glm::dvec3(1.0));
    ls.last_voxel = glm::dvec3(li.extent - glm::u64vec3(1u));
    ls.bricks = li.bricks;
    scales_.push_back(ls);
  }
  offsets_.reserve(table_count() + 1u);
  std::uint32_t at = 0;
  for (std::uint32_t s = 0; s < slots_; ++s) {
    for (std::uint32_t l = 0; l < levels_; ++l) {
      offsets_.push_back(at);
      at += std::uint32_t(hierarchy.level(l).brick_count);
    }
  }
  offsets_.push_back(at);
  try {
    entries_.assign(at, k::RESOCT_PAGE_UNMAPPED_WORD);
    dirty_bits_.assign((std::size_t(at) + 63u) / 64u, 0u);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory,
                "slots: no host memory for " + std::to_string(at) + " page-table entries");
  }
}

void PageTable::check_slot(std::uint32_t slot) const {
  if (slot >= slots_) {
    throw Error(ErrorCode::out_of_range, "slot " + std::to_string(slot) + " out of range (" +
                                             std::to_string(slots_) + " slots)");
  }
}

std::uint32_t PageTable::table_id(std::uint32_t slot, std::uint32_t level) const {
  check_slot(slot);
  if (level >= levels_) {
    throw Error(ErrorCode::out_of_range, "level " + std::to_string(level) + " out of range (" +
                                             std::to_string(levels_) + " levels)");
  }
  return k::resoct_request_table_id(slot, level, levels_);
}

std::uint32_t PageTable::entry_index(const PageAddress& a) const {
  const std::uint32_t t = table_id(a.slot, a.level);
  const LevelInfo& li = hierarchy_.level(a.level);
  if (a.brick.x >= li.bricks.x || a.brick.y >= li.bricks.y || a.brick.z >= li.bricks.z) {
    throw Error(ErrorCode::out_of_range,
                "brick (" + std::to_string(a.brick.x) + ", " + std::to_string(a.brick.y) + ", " +
                    std::to_string(a.brick.z) + ") outside level " + std::to_string(a.level));
  }
  return offsets_[t] + k::resoct_page_local_index(a.brick, li.bricks);
}

PageLookup PageTable::translate(std::uint32_t level, std::uint32_t slot,
                                const glm::dvec3& p) const {
  const std::uint32_t t = table_id(slot, level);
  const LevelScale& ls = scales_[level];
  const glm::uvec3 b = hierarchy_.layout().brick_size;
  const std::uint32_t halo = hierarchy_.layout().halo;
  PageLookup out;
  for (int i = 0; i < 3; ++i) {
    // Voxel first, then brick (floor(floor(x) / b)): correct for partial border bricks. p = 1
    // lands on the far face and belongs to the last voxel.
    const double c = p[i] > 0.0 ? std::min(p[i], 1.0) : 0.0;  // NaN reads as 0
    const double x = c * ls.scale[i];
    out.voxel[i] = std::uint32_t(std::min(std::floor(x), ls.last_voxel[i]));
    out.brick[i] = out.voxel[i] / b[i];
    out.padded_offset[i] = out.voxel[i] - out.brick[i] * b[i] + halo;
  }
  out.entry_index = offsets_[t] + k::resoct_page_local_index(out.brick, ls.bricks);
  out.entry = entries_[out.entry_index];
  return out;
}

void PageTable::store(std::uint32_t index, std::uint32_t value) {
  if (entries_[index] == value) return;
  if (k::resoct_page_state(entries_[index]) == k::RESOCT_PAGE_STATE_HOMOGENEOUS)
    homogeneous_.erase(index);
  entries_[index] = value;
  std::uint64_t& word = dirty_bits_[index / 64u];
  const std::uint64_t bit = std::uint64_t(1) << (index % 64u);
  if ((word & bit) == 0) {
    word |= bit;
    dirty_list_.push_back(index);
  }
}

void PageTable::set_mapped(const PageAddress& a, std::uint32_t cache_slot) {
  if (cache_slot > k::RESOCT_PAGE_MAX_CACHE_SLOT) {
    throw invalid_parameter("cache_slot", std::to_string(cache_slot) + " exceeds the 30-bit " +
                                              "slot field of a page entry");
  }
  store(entry_index(a), k::resoct_page_encode_mapped(cache_slot));
}

void PageTable::set_empty(const PageAddress& a) {
  store(entry_index(a), k::RESOCT_PAGE_EMPTY_WORD);
}

void PageTable::set_unmapped(const PageAddress& a) {
  store(entry_index(a), k::RESOCT_PAGE_UNMAPPED_WORD);
}

void PageTable::set_homogeneous(const PageAddress& a, double value, const ValueRange& range) {
  if (!std::isfinite(value)) throw invalid_parameter("value", "homogeneous value must be finite");
  const std::uint32_t i = entry_index(a);
  const double span = range.hi - range.lo;
  const double t = span > 0.0 ? std::clamp((value - range.lo) / span, 0.0, 1.0) : 0.0;
  const std::uint32_t q = std::uint32_t(std::lround(t * 65535.0));
  store(i, k::resoct_page_encode_homogeneous(q));
  homogeneous_[i] = value;  // after store(): a HOMOGENEOUS -> HOMOGENEOUS change keeps the value
}

std::optional<double> PageTable::homogeneous_value(const PageAddress& a) const {
  const std::uint32_t i = entry_index(a);
  if (k::resoct_page_state(entries_[i]) != k::RESOCT_PAGE_STATE_HOMOGENEOUS) return std::nullopt;
  return homogeneous_.at(i);
}

std::vector<std::uint32_t> PageTable::clear_slot(std::uint32_t slot) {
  check_slot(slot);
  std::vector<std::uint32_t> released;
  const std::uint32_t begin = offsets_[table_id(slot, 0)];
  const std::uint32_t end = offsets_[table_id(slot, levels_ - 1u) + 1u];
  for (std::uint32_t i = begin; i < end; ++i) {
    if (k::resoct_page_is_mapped(entries_[i]))
      released.push_back(k::resoct_page_cache_slot(entries_[i]));
    store(i, k::RESOCT_PAGE_UNMAPPED_WORD);
  }
  return released;
}

std::uint32_t PageTable::device_key(const PageAddress& a) const {
  const std::uint32_t i = entry_index(a);  // validates
  const std::uint32_t t = table_id(a.slot, a.level);
  return k::resoct_request_key_encode(t, i - offsets_[t]);
}

std::optional<PageAddress> PageTable::decode_device_key(std::uint32_t key) const {
  const std::uint32_t t = k::resoct_request_key_table(key);
  if (key == k::RESOCT_REQUEST_KEY_NONE || t >= table_count()) return std::nullopt;
  PageAddress a;
  a.slot = t / levels_;
  a.level = t % levels_;
  const LevelInfo& li = hierarchy_.level(a.level);
  std::uint32_t r = k::resoct_request_key_local(key);
  if (r >= li.brick_count) return std::nullopt;
  a.brick.x = r % li.bricks.x;
  r /= li.bricks.x;
  a.brick.y = r % li.bricks.y;
  a.brick.z = r / li.bricks.y;
  return a;
}

std::vector<PageDelta> PageTable::take_deltas() {
  std::sort(dirty_list_.begin(), dirty_list_.end());
  std::vector<PageDelta> out;
  out.reserve(dirty_list_.size());
  for (std::uint32_t i : dirty_list_) {
    out.push_back({i, entries_[i]});
    dirty_bits_[i / 64u] &= ~(std::uint64_t(1) << (i % 64u));
  }
  dirty_list_.clear();
  return out;
}

}  // namespace resoct
