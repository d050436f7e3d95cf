#pragma once
/// \file
/// A BrickSource over a DenseVolume: every coarser level is computed once at construction by
/// repeated downsampling (see downsample.hpp) and kept in memory.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "resoct/sources/brick_source.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/sources/metadata_pyramid.hpp"

namespace resoct {

/// Serves bricks of a DenseVolume. Level l is downsample() of level l - 1 with the axes
/// BrickHierarchy halves between them; read_brick copies core plus halo, clamping to the edge of
/// the level. region_meta answers from a MetadataPyramid over the level-0 voxels, brick_meta
/// scans the padded brick. Memory: the dense volume plus about 1/7 of it (1/3 for 2x2x1 levels).
/// Immutable after construction; all members are thread-safe.
class InMemorySource : public BrickSource {
 public:
  /// Throws Error when the layout or `metadata_block` (power of two, 4..1024) is invalid, or
  /// `volume` is empty (default-constructed).
  InMemorySource(DenseVolume volume, BrickLayout layout = {}, std::uint32_t metadata_block = 16,
                 std::string name = "memory");

  const BrickHierarchy& hierarchy() const override { return hierarchy_; }
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override;
  std::string name() const override { return name_; }

  const DenseVolume& dense() const noexcept { return volume_; }
  const MetadataPyramid& metadata() const noexcept { return pyramid_; }
  /// All voxels of one channel at one level (dense, x fastest). Throws Error(out_of_range).
  std::span<const std::byte> level_voxels(std::uint32_t level, std::uint32_t channel) const;

 private:
  DenseVolume volume_;
  BrickHierarchy hierarchy_;
  std::string name_;
  std::vector<std::vector<std::byte>> coarse_;  // levels 1.., channel-major
  MetadataPyramid pyramid_;
};

}  // namespace resoct
