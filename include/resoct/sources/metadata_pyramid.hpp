#pragma once
/// \file
/// Conservative per-block metadata of level-0 voxels (min, max, value occupancy), reduced into a
/// pyramid so that a region query reads a bounded number of entries at any region size. This is
/// how sources answer BrickSource::region_meta without touching voxels; the brick store
/// persists it.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/box.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

class MetadataPyramid {
 public:
  MetadataPyramid() = default;
  /// An empty pyramid (every block "only NaN") over a level-0 extent, with cubic blocks of
  /// `block_size` voxels (a power of two, 4..1024) and `channels` channels.
  MetadataPyramid(glm::u64vec3 extent0, std::uint32_t block_size, std::uint32_t channels);

  std::uint32_t block_size() const noexcept { return block_size_; }
  std::uint32_t channels() const noexcept { return channels_; }
  glm::u64vec3 extent0() const noexcept { return extent0_; }
  /// Blocks per axis at pyramid level 0 (the finest): ceil(extent0 / block_size).
  glm::u64vec3 blocks() const noexcept {
    return levels_.empty() ? glm::u64vec3(0) : levels_[0].dim;
  }
  std::uint32_t pyramid_levels() const noexcept { return std::uint32_t(levels_.size()); }

  /// Finest-level entries of a channel, x fastest (for filling and for serialization).
  std::span<RegionMeta> finest(std::uint32_t channel);
  std::span<const RegionMeta> finest(std::uint32_t channel) const;

  /// Widens one finest block (thread-safe for distinct blocks only).
  void merge_block(std::uint32_t channel, const glm::u64vec3& block, const RegionMeta& m);

  /// Recomputes every coarser pyramid level from the finest one (min of min, max of max, OR of
  /// occupancy). Call after filling and before querying.
  void build();

  /// Conservative metadata of `channel` over the level-0 region (clamped to the volume): the
  /// merge of the entries of the finest pyramid level at which the region touches at most 64
  /// entries. An empty or outside region gives the "only NaN" RegionMeta.
  RegionMeta query(std::uint32_t channel, const Box3& level0_region) const;

 private:
  struct Level {
    glm::u64vec3 dim{0};
    std::vector<RegionMeta> entries;  // channels * dim.x * dim.y * dim.z, channel-major
  };
  std::size_t index(const Level& lv, std::uint32_t channel, const glm::u64vec3& b) const;

  glm::u64vec3 extent0_{0};
  std::uint32_t block_size_ = 0;
  std::uint32_t channels_ = 0;
  std::vector<Level> levels_;
};

/// Metadata of a dense buffer of `count` voxels of type t over range r (NaN ignored).
RegionMeta scan_region(std::span<const std::byte> voxels, VoxelType t, const ValueRange& r);

}  // namespace resoct
