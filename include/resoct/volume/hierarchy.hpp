#pragma once
/// \file
/// The brick hierarchy: resolution levels, bricks per level, and the address arithmetic between
/// normalized positions, level voxels and bricks. See docs/hierarchy.md.

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/box.hpp"
#include "resoct/volume/brick_key.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

/// How a volume is cut into bricks. Every brick of every level has the same core size plus a
/// halo of `halo` voxels on each side, copied from same-level neighbours (clamped to the edge
/// outside the volume), so that trilinear sampling needs no neighbour brick.
struct BrickLayout {
  glm::uvec3 brick_size{32};  ///< core voxels per axis, each >= 4
  std::uint32_t halo = 1;     ///< ghost voxels per side, 0..4

  /// Core plus halo on both sides: the size of one cache slot.
  glm::uvec3 padded_size() const noexcept { return brick_size + 2u * glm::uvec3(halo); }
  std::uint64_t padded_voxels() const noexcept {
    const glm::uvec3 p = padded_size();
    return std::uint64_t(p.x) * p.y * p.z;
  }
  /// Throws Error(invalid_argument) naming "brick_size" or "halo" when out of range.
  void validate() const;
  friend bool operator==(const BrickLayout&, const BrickLayout&) = default;
};

/// One resolution level. Level l voxel i covers level-0 voxels [i << f, (i + 1) << f) per axis,
/// f = factor_log2; its extent is ceil(extent0 / 2^f), so the last voxel of an odd level may
/// reach past the volume (it averages only the voxels that exist).
struct LevelInfo {
  glm::u64vec3 extent{1};         ///< voxels per axis at this level
  glm::uvec3 factor_log2{0};      ///< per-axis downsampling exponent relative to level 0
  glm::uvec3 bricks{1};           ///< bricks per axis: ceil(extent / brick_size)
  std::uint64_t brick_count = 1;  ///< bricks in this level (one channel)
  std::uint64_t first_brick = 0;  ///< linear index of this level's first brick (one channel)
};

class BrickHierarchy {
 public:
  /// Builds the level chain. Each coarser level halves an axis (rounding up) or keeps it whole:
  /// an axis is halved only while it still spans more than one brick and is not much smaller than
  /// the largest axis (measured in bricks, it must exceed half of the largest), so a
  /// 1024×1024×40 volume goes 2×2×1 first. Levels continue until one brick covers the volume.
  /// Throws Error when the description or layout is invalid or a level has more bricks per axis
  /// than BrickKey can hold.
  BrickHierarchy(VolumeDesc volume, BrickLayout layout);

  const VolumeDesc& volume() const noexcept { return volume_; }
  const BrickLayout& layout() const noexcept { return layout_; }
  std::uint32_t level_count() const noexcept { return std::uint32_t(levels_.size()); }
  const LevelInfo& level(std::uint32_t l) const { return levels_.at(l); }
  const std::vector<LevelInfo>& levels() const noexcept { return levels_; }

  /// Bricks of all levels in one channel; linear indices run level by level, x fastest.
  std::uint64_t bricks_per_channel() const noexcept { return bricks_per_channel_; }

  /// Position of normalized p (each axis [0, 1] over the level-0 extent) in level-l voxel units:
  /// p * extent0 / 2^factor. Not clamped.
  glm::dvec3 level_voxel_position(std::uint32_t l, const glm::dvec3& p) const;

  /// The brick containing normalized p at level l: floor(floor(x_l) / b) with x_l the level
  /// voxel position, clamped to the level's bricks (so p = 1 lands in the last brick).
  glm::uvec3 brick_at(std::uint32_t l, const glm::dvec3& p) const;

  /// Core voxels of a brick in level-l voxel coordinates (partial at the far borders).
  Box3 core_box(std::uint32_t l, const glm::uvec3& brick) const;
  /// Core plus halo in level-l voxel coordinates (may extend outside the level).
  Box3 padded_box(std::uint32_t l, const glm::uvec3& brick) const;
  /// The level-0 voxels a brick's core covers, clamped to the volume.
  Box3 level0_box(std::uint32_t l, const glm::uvec3& brick) const;
  /// Level-l voxels whose footprint intersects a level-0 box.
  Box3 level_box_from_level0(std::uint32_t l, const Box3& level0) const;

  /// Linear index of a brick within one channel (see bricks_per_channel()).
  std::uint64_t linear_index(std::uint32_t l, const glm::uvec3& brick) const;
  /// Inverse of linear_index; throws Error(out_of_range) past the last brick.
  BrickKey key_from_linear(std::uint32_t channel, std::uint64_t index) const;

  /// True when the key names an existing brick of an existing level and channel.
  bool contains(BrickKey key) const noexcept;

  friend bool operator==(const BrickHierarchy& a, const BrickHierarchy& b) {
    return a.volume_ == b.volume_ && a.layout_ == b.layout_;
  }

 private:
  VolumeDesc volume_;
  BrickLayout layout_;
  std::vector<LevelInfo> levels_;
  std::uint64_t bricks_per_channel_ = 0;
};

}  // namespace resoct
