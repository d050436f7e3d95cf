#pragma once
/// \file
/// The multi-channel page table: one table per (visible channel slot, level), flat and
/// device-ready, with a delta list so backends receive only changed entries.

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/hierarchy.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/voxel_type.hpp"

namespace resoct {

/// One changed entry: its index in entries() and its value at take_deltas() time.
struct PageDelta {
  std::uint32_t index = 0;
  std::uint32_t value = 0;
  friend bool operator==(const PageDelta&, const PageDelta&) = default;
};

/// A brick as the page table sees it: visible slot, level, brick coordinates.
struct PageAddress {
  std::uint32_t slot = 0;
  std::uint32_t level = 0;
  glm::uvec3 brick{0};
  friend bool operator==(const PageAddress&, const PageAddress&) = default;
};

/// Result of virtual address translation (thesis Eq. 5.1-5.3 with the partial-brick fix).
struct PageLookup {
  std::uint32_t entry_index = 0;  ///< index into entries()
  std::uint32_t entry = 0;        ///< the entry word (see kernel/page_entry.glsl.h)
  glm::uvec3 brick{0};            ///< brick coordinates at the level
  glm::uvec3 voxel{0};            ///< level voxel, clamped to the level extent
  glm::uvec3 padded_offset{0};    ///< voxel within the padded brick: core offset + halo

  bool mapped() const noexcept { return kernel::resoct_page_is_mapped(entry); }
  /// Cache slot of a MAPPED entry, nullopt otherwise.
  std::optional<std::uint32_t> cache_slot() const noexcept {
    if (!mapped()) return std::nullopt;
    return kernel::resoct_page_cache_slot(entry);
  }
};

/// Host-authoritative page table. Table id t = slot * level_count + level; table t occupies
/// entries [table_offsets()[t], table_offsets()[t + 1]), bricks x fastest. Entries start
/// UNMAPPED. Every change is remembered (deduplicated) until take_deltas().
/// Thread-safety: none; one thread owns it (the frame loop). Const members may run concurrently.
class PageTable {
 public:
  /// Throws Error(invalid_argument) naming "slots" when slots is 0, or when the hierarchy does not
  /// fit 32-bit device request keys (kernel/request_key.glsl.h): more than 128 (slot, level)
  /// tables, a level with 2^25 - 1 or more bricks, or more than 2^32 - 1 entries in total;
  /// Error(out_of_memory) when the host cannot hold the entries.
  PageTable(const BrickHierarchy& hierarchy, std::uint32_t slots);

  const BrickHierarchy& hierarchy() const noexcept { return hierarchy_; }
  std::uint32_t slot_count() const noexcept { return slots_; }
  std::uint32_t level_count() const noexcept { return levels_; }
  std::uint32_t table_count() const noexcept { return slots_ * levels_; }
  std::uint32_t table_id(std::uint32_t slot, std::uint32_t level) const;

  /// All entries of all tables (upload this once, then apply deltas).
  const std::vector<std::uint32_t>& entries() const noexcept { return entries_; }
  /// table_count() + 1 offsets into entries(); the last one is entries().size().
  const std::vector<std::uint32_t>& table_offsets() const noexcept { return offsets_; }

  /// Index in entries() of a brick; throws Error(out_of_range) for a brick outside the level.
  std::uint32_t entry_index(const PageAddress& a) const;
  std::uint32_t entry(const PageAddress& a) const { return entries_[entry_index(a)]; }

  /// Translates normalized p (clamped to [0, 1]) at a level and slot to the entry and the voxel
  /// inside the padded brick. O(1).
  PageLookup translate(std::uint32_t level, std::uint32_t slot, const glm::dvec3& p) const;

  void set_mapped(const PageAddress& a, std::uint32_t cache_slot);
  void set_empty(const PageAddress& a);
  void set_unmapped(const PageAddress& a);
  /// Marks a constant brick. The device entry holds the value as unorm16 of `range`; the exact
  /// value is kept on the host (homogeneous_value()).
  void set_homogeneous(const PageAddress& a, double value, const ValueRange& range);
  /// Exact value of a HOMOGENEOUS entry, nullopt for other states.
  std::optional<double> homogeneous_value(const PageAddress& a) const;

  /// Sets every entry of the slot's tables to UNMAPPED (recording deltas) and returns the cache
  /// slots that were MAPPED there, which the caller must release. O(entries of the slot).
  std::vector<std::uint32_t> clear_slot(std::uint32_t slot);

  /// The 32-bit device request key of a brick (kernel/request_key.glsl.h).
  std::uint32_t device_key(const PageAddress& a) const;
  /// Inverse of device_key; nullopt for keys that name no brick (device keys are not trusted).
  std::optional<PageAddress> decode_device_key(std::uint32_t key) const;

  /// Changed entries since the last call, one per index, sorted by index, with current values.
  std::vector<PageDelta> take_deltas();
  std::size_t pending_delta_count() const noexcept { return dirty_list_.size(); }

 private:
  void store(std::uint32_t index, std::uint32_t value);
  void check_slot(std::uint32_t slot) const;

  // Per-level constants of translate(): level voxels per unit of p (extent0 / 2^f, exact because
  // the divisor is a power of two, so p * scale equals level_voxel_position), last voxel, bricks.
  struct LevelScale {
    glm::dvec3 scale{1.0};
    glm::dvec3 last_voxel{0.0};
    glm::uvec3 bricks{1};
  };

  BrickHierarchy hierarchy_;
  std::vector<LevelScale> scales_;
  std::uint32_t slots_ = 0;
  std::uint32_t levels_ = 0;
  std::vector<std::uint32_t> entries_;
  std::vector<std::uint32_t> offsets_;
  std::vector<std::uint64_t> dirty_bits_;  // one bit per entry: already in dirty_list_
  std::vector<std::uint32_t> dirty_list_;
  std::unordered_map<std::uint32_t, double> homogeneous_;  // exact values by entry index
};

}  // namespace resoct
