#include "resoct/engine/page_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct {

namespace k = resoct::kernel;

namespace {

constexpr std::uint32_t kBlockEntries = k::RESOCT_PAGE_BLOCK_ENTRIES;

template <class T>
void grow(std::vector<T>& v, std::size_t n, const T& value, const char* what) {
  try {
    v.resize(n, value);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory, std::string("page table: no host memory for ") + what);
  }
}

void mark_dirty(std::vector<std::uint64_t>& bits, std::vector<std::uint32_t>& list,
                std::uint32_t index) {
  std::uint64_t& word = bits[index / 64u];
  const std::uint64_t bit = std::uint64_t(1) << (index % 64u);
  if ((word & bit) == 0) {
    word |= bit;
    list.push_back(index);
  }
}

std::vector<PageDelta> drain(std::vector<std::uint64_t>& bits, std::vector<std::uint32_t>& list,
                             const std::vector<std::uint32_t>& values) {
  std::sort(list.begin(), list.end());
  std::vector<PageDelta> out;
  out.reserve(list.size());
  for (std::uint32_t i : list) {
    out.push_back({i, values[i]});
    bits[i / 64u] &= ~(std::uint64_t(1) << (i % 64u));
  }
  list.clear();
  return out;
}

}  // namespace

std::uint64_t PageTable::block_count(const BrickHierarchy& hierarchy, std::uint32_t slots) {
  std::uint64_t per_slot = 0;
  for (std::uint32_t l = 0; l < hierarchy.level_count(); ++l) {
    const glm::u64vec3 b = hierarchy.level(l).bricks;
    const glm::u64vec3 n = (b + glm::u64vec3(k::RESOCT_PAGE_BLOCK_MASK)) >> glm::u64vec3(4u);
    per_slot += n.x * n.y * n.z;
  }
  return per_slot * slots;
}

PageTable::PageTable(const BrickHierarchy& hierarchy, std::uint32_t slots, std::uint32_t max_blocks)
    : hierarchy_(hierarchy),
      slots_(slots),
      levels_(hierarchy.level_count()),
      max_blocks_(max_blocks) {
  if (slots == 0) throw invalid_parameter("slots", "at least one visible channel slot is needed");
  if (max_blocks == 0) throw invalid_parameter("max_blocks", "at least one pool block is needed");
  if (std::uint64_t(max_blocks) + 1u > k::RESOCT_REQUEST_MAX_POOL_BLOCKS) {
    throw invalid_parameter("max_blocks",
                            std::to_string(max_blocks) + " pool blocks exceed the " +
                                std::to_string(k::RESOCT_REQUEST_MAX_POOL_BLOCKS - 1u) +
                                " that 32-bit device request keys address");
  }
  const std::uint64_t dir = block_count(hierarchy, slots);
  if (dir >= k::RESOCT_REQUEST_MAX_DIRECTORY) {
    throw invalid_parameter("slots", "page-table directory would need " + std::to_string(dir) +
                                         " entries, at most " +
                                         std::to_string(k::RESOCT_REQUEST_MAX_DIRECTORY - 1u) +
                                         " fit 32-bit device keys; use bigger bricks or fewer "
                                         "visible slots");
  }
  for (std::uint32_t l = 0; l < levels_; ++l) {
    const LevelInfo& li = hierarchy.level(l);
    LevelScale ls;
    ls.scale = hierarchy.level_voxel_position(l, glm::dvec3(1.0));
    ls.last_voxel = glm::dvec3(li.extent - glm::u64vec3(1u));
    ls.bricks = li.bricks;
    scales_.push_back(ls);
  }
  dir_offsets_.reserve(std::size_t(table_count()) + 1u);
  std::uint32_t at = 0;
  for (std::uint32_t s = 0; s < slots_; ++s) {
    for (std::uint32_t l = 0; l < levels_; ++l) {
      dir_offsets_.push_back(at);
      const glm::uvec3 n = k::resoct_page_blocks(hierarchy.level(l).bricks);
      at += n.x * n.y * n.z;
    }
  }
  dir_offsets_.push_back(at);
  grow(directory_, at, 0u, "the directory");
  grow(dir_dirty_bits_, (std::size_t(at) + 63u) / 64u, std::uint64_t(0), "the directory");
  // Pool block 0: the permanent all-UNMAPPED block.
  grow(pool_, kBlockEntries, k::RESOCT_PAGE_UNMAPPED_WORD, "the page pool");
  grow(pool_dirty_bits_, kBlockEntries / 64u, std::uint64_t(0), "the page pool");
  blocks_.resize(1);
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

std::uint32_t PageTable::directory_index(const PageAddress& a) const {
  const std::uint32_t t = table_id(a.slot, a.level);
  const LevelInfo& li = hierarchy_.level(a.level);
  if (a.brick.x >= li.bricks.x || a.brick.y >= li.bricks.y || a.brick.z >= li.bricks.z) {
    throw Error(ErrorCode::out_of_range,
                "brick (" + std::to_string(a.brick.x) + ", " + std::to_string(a.brick.y) + ", " +
                    std::to_string(a.brick.z) + ") outside level " + std::to_string(a.level));
  }
  return dir_offsets_[t] + k::resoct_page_block_index(a.brick, li.bricks);
}

std::uint32_t PageTable::table_of_directory(std::uint32_t d) const {
  const auto it = std::upper_bound(dir_offsets_.begin(), dir_offsets_.end(), d);
  return std::uint32_t(it - dir_offsets_.begin()) - 1u;
}

std::uint32_t PageTable::entry(const PageAddress& a) const {
  const std::uint32_t block = directory_[directory_index(a)];
  return pool_[std::size_t(block) * kBlockEntries + k::resoct_page_in_block_index(a.brick)];
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
  const std::uint32_t block =
      directory_[dir_offsets_[t] + k::resoct_page_block_index(out.brick, ls.bricks)];
  out.entry = pool_[std::size_t(block) * kBlockEntries + k::resoct_page_in_block_index(out.brick)];
  return out;
}

void PageTable::store_pool(std::uint32_t index, std::uint32_t value) {
  if (pool_[index] == value) return;
  if (k::resoct_page_state(pool_[index]) == k::RESOCT_PAGE_STATE_HOMOGENEOUS)
    homogeneous_.erase(index);
  pool_[index] = value;
  mark_dirty(pool_dirty_bits_, pool_dirty_list_, index);
}

void PageTable::store_dir(std::uint32_t index, std::uint32_t value) {
  if (directory_[index] == value) return;
  directory_[index] = value;
  mark_dirty(dir_dirty_bits_, dir_dirty_list_, index);
}

void PageTable::touch(std::uint32_t block) {
  BlockInfo& info = blocks_[block];
  reclaimable_.erase({info.stamp, block});
  info.stamp = ++clock_;
  if (info.mapped == 0) reclaimable_.insert({info.stamp, block});
}

void PageTable::release_block(std::uint32_t block) {
  const std::size_t base = std::size_t(block) * kBlockEntries;
  for (std::uint32_t i = 0; i < kBlockEntries; ++i) {
    if (pool_[base + i] != k::RESOCT_PAGE_UNMAPPED_WORD)
      store_pool(std::uint32_t(base + i), k::RESOCT_PAGE_UNMAPPED_WORD);
  }
  BlockInfo& info = blocks_[block];
  store_dir(info.owner, 0u);
  reclaimable_.erase({info.stamp, block});
  info = BlockInfo{};
  free_.push_back(block);
  --allocated_;
}

std::uint32_t PageTable::take_block() {
  if (free_.empty()) {
    if (blocks_.size() < pool_block_count()) {
      const std::size_t n = blocks_.size() + 1u;
      grow(pool_, n * kBlockEntries, k::RESOCT_PAGE_UNMAPPED_WORD, "the page pool");
      grow(pool_dirty_bits_, n * kBlockEntries / 64u, std::uint64_t(0), "the page pool");
      blocks_.resize(n);
      free_.push_back(std::uint32_t(n - 1u));
    } else {
      if (reclaimable_.empty()) {
        throw invalid_parameter("max_blocks",
                                "all " + std::to_string(max_blocks_) +
                                    " page-table pool blocks hold MAPPED entries; the pool must "
                                    "have more blocks than the device cache has slots");
      }
      release_block(reclaimable_.begin()->second);
    }
  }
  const std::uint32_t block = free_.back();
  free_.pop_back();
  ++allocated_;
  return block;
}

void PageTable::allocate_block(std::uint32_t directory_index) {
  if (directory_index >= directory_.size()) {
    throw Error(ErrorCode::out_of_range, "directory index " + std::to_string(directory_index) +
                                             " out of range (" + std::to_string(directory_.size()) +
                                             " entries)");
  }
  if (directory_[directory_index] != 0u) return;
  const std::uint32_t block = take_block();
  blocks_[block].owner = directory_index;
  store_dir(directory_index, block);
  touch(block);
}

void PageTable::store(const PageAddress& a, std::uint32_t value) {
  const std::uint32_t d = directory_index(a);
  if (directory_[d] == 0u) {
    if (value == k::RESOCT_PAGE_UNMAPPED_WORD) return;
    allocate_block(d);
  }
  const std::uint32_t block = directory_[d];
  const std::uint32_t i = block * kBlockEntries + k::resoct_page_in_block_index(a.brick);
  const std::uint32_t old = pool_[i];
  if (old == value) return;
  BlockInfo& info = blocks_[block];
  if (k::resoct_page_is_mapped(old)) --info.mapped;
  if (k::resoct_page_is_mapped(value)) ++info.mapped;
  store_pool(i, value);
  touch(block);
}

void PageTable::set_mapped(const PageAddress& a, std::uint32_t cache_slot,
                           std::uint32_t error_code) {
  if (cache_slot > k::RESOCT_PAGE_MAX_CACHE_SLOT) {
    throw invalid_parameter("cache_slot", std::to_string(cache_slot) + " exceeds the 26-bit " +
                                              "slot field of a page entry");
  }
  if (error_code > k::RESOCT_PAGE_ERROR_MAX) {
    throw invalid_parameter("error_code", std::to_string(error_code) + " exceeds 15");
  }
  store(a, k::resoct_page_with_error(k::resoct_page_encode_mapped(cache_slot), error_code));
}

void PageTable::set_empty(const PageAddress& a) {
  store(a, k::RESOCT_PAGE_EMPTY_WORD);
}

void PageTable::set_no_finite(const PageAddress& a) {
  store(a, k::RESOCT_PAGE_EMPTY_NAN_WORD);
}

void PageTable::set_unmapped(const PageAddress& a) {
  store(a, k::RESOCT_PAGE_UNMAPPED_WORD);
}

void PageTable::set_homogeneous(const PageAddress& a, double value, const ValueRange& range,
                                std::uint32_t error_code) {
  if (!std::isfinite(value)) throw invalid_parameter("value", "homogeneous value must be finite");
  if (error_code > k::RESOCT_PAGE_ERROR_MAX) {
    throw invalid_parameter("error_code", std::to_string(error_code) + " exceeds 15");
  }
  const double span = range.hi - range.lo;
  const double t = span > 0.0 ? std::clamp((value - range.lo) / span, 0.0, 1.0) : 0.0;
  const std::uint32_t q = std::uint32_t(std::lround(t * 65535.0));
  store(a, k::resoct_page_with_error(k::resoct_page_encode_homogeneous(q), error_code));
  // After store(): a HOMOGENEOUS -> HOMOGENEOUS change keeps the value.
  const std::uint32_t block = directory_[directory_index(a)];
  homogeneous_[block * kBlockEntries + k::resoct_page_in_block_index(a.brick)] = value;
}

std::optional<double> PageTable::homogeneous_value(const PageAddress& a) const {
  const std::uint32_t block = directory_[directory_index(a)];
  const std::uint32_t i = block * kBlockEntries + k::resoct_page_in_block_index(a.brick);
  if (k::resoct_page_state(pool_[i]) != k::RESOCT_PAGE_STATE_HOMOGENEOUS) return std::nullopt;
  return homogeneous_.at(i);
}

std::vector<std::uint32_t> PageTable::clear_slot(std::uint32_t slot) {
  check_slot(slot);
  std::vector<std::uint32_t> released;
  for (std::uint32_t b = 1; b < blocks_.size(); ++b) {
    if (blocks_[b].owner == kNoOwner || table_of_directory(blocks_[b].owner) / levels_ != slot)
      continue;
    const std::size_t base = std::size_t(b) * kBlockEntries;
    for (std::uint32_t i = 0; i < kBlockEntries && blocks_[b].mapped > 0; ++i) {
      if (k::resoct_page_is_mapped(pool_[base + i])) {
        released.push_back(k::resoct_page_cache_slot(pool_[base + i]));
      }
    }
    release_block(b);
  }
  return released;
}

std::uint32_t PageTable::device_key(const PageAddress& a) const {
  const std::uint32_t d = directory_index(a);  // validates
  const std::uint32_t block = directory_[d];
  if (block == 0u) return k::resoct_request_key_block_miss(d);
  return k::resoct_request_key_brick(block, k::resoct_page_in_block_index(a.brick));
}

std::optional<PageAddress> PageTable::decode_device_key(std::uint32_t key) const {
  if (key == k::RESOCT_REQUEST_KEY_NONE || k::resoct_request_key_is_block_miss(key))
    return std::nullopt;
  const std::uint32_t block = k::resoct_request_key_pool_block(key);
  if (block == 0u || block >= blocks_.size() || blocks_[block].owner == kNoOwner)
    return std::nullopt;
  const std::uint32_t d = blocks_[block].owner;
  const std::uint32_t t = table_of_directory(d);
  PageAddress a;
  a.slot = t / levels_;
  a.level = t % levels_;
  const glm::uvec3 bricks = hierarchy_.level(a.level).bricks;
  const glm::uvec3 n = k::resoct_page_blocks(bricks);
  std::uint32_t r = d - dir_offsets_[t];
  glm::uvec3 blk;
  blk.x = r % n.x;
  r /= n.x;
  blk.y = r % n.y;
  blk.z = r / n.y;
  const std::uint32_t in = k::resoct_request_key_in_block(key);
  const glm::uvec3 local(in & 15u, (in >> 4u) & 15u, in >> 8u);
  a.brick = blk * 16u + local;
  if (a.brick.x >= bricks.x || a.brick.y >= bricks.y || a.brick.z >= bricks.z) return std::nullopt;
  return a;
}

std::optional<BlockMiss> PageTable::decode_block_miss(std::uint32_t key) const {
  if (key == k::RESOCT_REQUEST_KEY_NONE || !k::resoct_request_key_is_block_miss(key))
    return std::nullopt;
  const std::uint32_t d = k::resoct_request_key_directory(key);
  if (d >= directory_.size()) return std::nullopt;
  const std::uint32_t t = table_of_directory(d);
  return BlockMiss{t / levels_, t % levels_, d};
}

PageTableDeltas PageTable::take_deltas() {
  PageTableDeltas out;
  out.pool = drain(pool_dirty_bits_, pool_dirty_list_, pool_);
  out.directory = drain(dir_dirty_bits_, dir_dirty_list_, directory_);
  return out;
}

}  // namespace resoct
