#pragma once
/// \file
/// The multi-channel page table: one table per (visible channel slot, level), stored sparse in
/// two levels (a directory of 16^3-brick blocks over a fixed pool of blocks, device-ready), with
/// delta lists so backends receive only changed words.

#include <cstdint>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/engine/device_records.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// The changes of both arrays since the last take_deltas(), each sorted by index.
struct PageTableDeltas {
  std::vector<PageDelta> pool;       ///< index = pool block * 4096 + entry in block
  std::vector<PageDelta> directory;  ///< index = global directory index
};

/// A brick as the page table sees it: visible slot, level, brick coordinates.
struct PageAddress {
  std::uint32_t slot = 0;
  std::uint32_t level = 0;
  glm::uvec3 brick{0};
  friend bool operator==(const PageAddress&, const PageAddress&) = default;
};

/// An unallocated block the device reported (a block-miss key, kernel/request_key.glsl.h).
struct BlockMiss {
  std::uint32_t slot = 0;
  std::uint32_t level = 0;
  std::uint32_t directory_index = 0;  ///< global index into directory()
  friend bool operator==(const BlockMiss&, const BlockMiss&) = default;
};

/// Result of virtual address translation (thesis Eq. 5.1-5.3 with the partial-brick fix).
struct PageLookup {
  std::uint32_t entry = 0;      ///< the entry word (see kernel/page_entry.glsl.h)
  glm::uvec3 brick{0};          ///< brick coordinates at the level
  glm::uvec3 voxel{0};          ///< level voxel, clamped to the level extent
  glm::uvec3 padded_offset{0};  ///< voxel within the padded brick: core offset + halo

  bool mapped() const noexcept { return kernel::resoct_page_is_mapped(entry); }
  /// Cache slot of a MAPPED entry, nullopt otherwise.
  std::optional<std::uint32_t> cache_slot() const noexcept {
    if (!mapped()) return std::nullopt;
    return kernel::resoct_page_cache_slot(entry);
  }
};

/// Host-authoritative sparse page table. Table id t = slot * level_count + level; table t's
/// blocks (16^3 bricks, partial at the far faces) occupy directory entries
/// [directory_offsets()[t], directory_offsets()[t + 1]), x fastest over its block grid. A
/// directory word is a pool block index; 0 = not allocated (pool block 0 stays all UNMAPPED).
/// Writing a non-UNMAPPED entry into an unallocated block allocates one; when all max_blocks are
/// in use, the least recently written block holding no MAPPED entry is reclaimed (its EMPTY and
/// HOMOGENEOUS entries are dropped: the frame loop re-derives them on the next request). Every
/// change is remembered (deduplicated) until take_deltas().
/// Thread-safety: none; one thread owns it (the frame loop). Const members may run concurrently.
class PageTable {
 public:
  /// `max_blocks` is the number of allocatable pool blocks (the device pool holds one more, the
  /// UNMAPPED block 0). Throws Error(invalid_argument) naming "slots" when slots is 0 or the
  /// directory of all (slot, level) tables would reach 2^31 - 1 entries, naming "max_blocks" when
  /// it is 0 or the pool would exceed 2^19 blocks (32-bit device request keys,
  /// kernel/request_key.glsl.h); Error(out_of_memory) when the host cannot hold the directory.
  PageTable(const BrickHierarchy& hierarchy, std::uint32_t slots, std::uint32_t max_blocks);

  /// Directory entries (blocks) of all tables of `slots` slots, without building a table.
  static std::uint64_t block_count(const BrickHierarchy& hierarchy, std::uint32_t slots);

  const BrickHierarchy& hierarchy() const noexcept { return hierarchy_; }
  std::uint32_t slot_count() const noexcept { return slots_; }
  std::uint32_t level_count() const noexcept { return levels_; }
  std::uint32_t table_count() const noexcept { return slots_ * levels_; }
  std::uint32_t table_id(std::uint32_t slot, std::uint32_t level) const;

  /// Allocatable pool blocks (capacity), blocks allocated now, and the device pool's size in
  /// blocks (max_blocks() + 1, block 0 included).
  std::uint32_t max_blocks() const noexcept { return max_blocks_; }
  std::uint32_t allocated_blocks() const noexcept { return allocated_; }
  std::uint32_t pool_block_count() const noexcept { return max_blocks_ + 1u; }

  /// Pool words of the blocks used so far (a prefix of the device pool; the rest is UNMAPPED).
  const std::vector<std::uint32_t>& pool() const noexcept { return pool_; }
  /// All directory entries of all tables (upload once, then apply deltas).
  const std::vector<std::uint32_t>& directory() const noexcept { return directory_; }
  /// table_count() + 1 offsets into directory(); the last one is directory().size().
  const std::vector<std::uint32_t>& directory_offsets() const noexcept { return dir_offsets_; }

  /// Global directory index of a brick's block; throws Error(out_of_range) for a brick outside
  /// the level or a bad slot / level.
  std::uint32_t directory_index(const PageAddress& a) const;
  /// The entry of a brick (UNMAPPED in an unallocated block); throws as directory_index().
  std::uint32_t entry(const PageAddress& a) const;

  /// Translates normalized p (clamped to [0, 1]) at a level and slot to the entry and the voxel
  /// inside the padded brick. O(1).
  PageLookup translate(std::uint32_t level, std::uint32_t slot, const glm::dvec3& p) const;

  /// Maps a brick to a cache slot; `error_code` is its down-sampling error code
  /// (brick_error_code(); 0 = unknown), which error-bounded LOD reads.
  void set_mapped(const PageAddress& a, std::uint32_t cache_slot, std::uint32_t error_code = 0);
  /// Marks a brick of only zeros (EMPTY, payload 0).
  void set_empty(const PageAddress& a);
  /// Marks a brick without any finite value (EMPTY, payload 1): transparent whatever the
  /// transfer function shows at 0.
  void set_no_finite(const PageAddress& a);
  void set_unmapped(const PageAddress& a);
  /// Marks a constant brick. The device entry holds the value as unorm16 of `range`; the exact
  /// value is kept on the host (homogeneous_value()).
  void set_homogeneous(const PageAddress& a, double value, const ValueRange& range,
                       std::uint32_t error_code = 0);
  /// Exact value of a HOMOGENEOUS entry, nullopt for other states.
  std::optional<double> homogeneous_value(const PageAddress& a) const;

  /// Sets every entry of the slot's tables to UNMAPPED and frees their blocks (recording deltas),
  /// returning the cache slots that were MAPPED there, which the caller must release.
  /// O(pool blocks in use).
  std::vector<std::uint32_t> clear_slot(std::uint32_t slot);

  /// Allocates the (all UNMAPPED) block of a directory entry unless it is allocated, reclaiming
  /// as described above. Throws Error(out_of_range) for a bad index, Error(invalid_argument)
  /// naming "max_blocks" when every block holds a MAPPED entry (cannot happen when max_blocks
  /// exceeds the cache slots).
  void allocate_block(std::uint32_t directory_index);

  /// The 32-bit device request key the kernel reports for a brick: its brick key when the block
  /// is allocated, else the block's block-miss key (kernel/request_key.glsl.h).
  std::uint32_t device_key(const PageAddress& a) const;
  /// The brick of a brick key; nullopt for block-miss keys and for keys that name no brick now
  /// (a free pool block, a brick beyond a partial block; device keys are not trusted).
  std::optional<PageAddress> decode_device_key(std::uint32_t key) const;
  /// The block of a block-miss key; nullopt for brick keys and out-of-range directory indices.
  std::optional<BlockMiss> decode_block_miss(std::uint32_t key) const;

  /// Changed words since the last call, one per index, sorted by index, with current values.
  PageTableDeltas take_deltas();
  std::size_t pending_delta_count() const noexcept {
    return pool_dirty_list_.size() + dir_dirty_list_.size();
  }

 private:
  static constexpr std::uint32_t kNoOwner = 0xFFFFFFFFu;

  std::uint32_t table_of_directory(std::uint32_t d) const;
  void store(const PageAddress& a, std::uint32_t value);
  void store_pool(std::uint32_t index, std::uint32_t value);
  void store_dir(std::uint32_t index, std::uint32_t value);
  std::uint32_t take_block();  // a free pool block, reclaiming if needed
  void release_block(std::uint32_t block);
  void touch(std::uint32_t block);
  void check_slot(std::uint32_t slot) const;

  // Per-level constants of translate(): level voxels per unit of p (extent0 / 2^f, exact because
  // the divisor is a power of two, so p * scale equals level_voxel_position), last voxel, bricks.
  struct LevelScale {
    glm::dvec3 scale{1.0};
    glm::dvec3 last_voxel{0.0};
    glm::uvec3 bricks{1};
  };
  // Host bookkeeping of one pool block.
  struct BlockInfo {
    std::uint32_t owner = kNoOwner;  // directory index, kNoOwner when free
    std::uint32_t mapped = 0;        // MAPPED entries
    std::uint64_t stamp = 0;         // last write (allocation or entry change)
  };

  BrickHierarchy hierarchy_;
  std::vector<LevelScale> scales_;
  std::uint32_t slots_ = 0;
  std::uint32_t levels_ = 0;
  std::uint32_t max_blocks_ = 0;
  std::uint32_t allocated_ = 0;
  std::uint64_t clock_ = 0;
  std::vector<std::uint32_t> directory_;
  std::vector<std::uint32_t> dir_offsets_;
  std::vector<std::uint32_t> pool_;  // grows block by block up to pool_block_count()
  std::vector<BlockInfo> blocks_;    // parallel to pool_ blocks
  std::vector<std::uint32_t> free_;  // freed blocks below the high-water mark
  std::set<std::pair<std::uint64_t, std::uint32_t>> reclaimable_;  // (stamp, block), no MAPPED
  std::vector<std::uint64_t> pool_dirty_bits_;  // one bit per pool word: in pool_dirty_list_
  std::vector<std::uint32_t> pool_dirty_list_;
  std::vector<std::uint64_t> dir_dirty_bits_;
  std::vector<std::uint32_t> dir_dirty_list_;
  std::unordered_map<std::uint32_t, double> homogeneous_;  // exact values by pool index
};

}  // namespace resoct
