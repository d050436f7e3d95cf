#pragma once
// Whole-level-0 passes of PyramidSource (internal): value ranges and the metadata pyramid, read
// tile by tile through a LevelBoxReader on several threads.

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "resoct/io/formats/pyramid_source.hpp"

namespace resoct::detail {

/// Finite (min, max) of every channel's level-0 voxels; (+inf, -inf) for a channel without any.
std::vector<std::pair<double, double>> scan_finite_minmax(const VolumeDesc& desc,
                                                          const LevelBoxReader& level0,
                                                          std::uint32_t threads);

/// Occupancy bit of every value of an integer type over r (empty for f32).
std::vector<std::uint32_t> occupancy_lut(VoxelType t, const ValueRange& r);

/// Widens out[i] by the voxels (dense, x fastest) of `box`, for every metadata block of edge
/// `block` that the box touches (x fastest over the block range of the box). `lut` is
/// occupancy_lut(t, r), or empty to compute every voxel's bit.
void block_metadata(VoxelType t, const Box3& box, std::span<const std::byte> voxels,
                    const ValueRange& r, const std::vector<std::uint32_t>& lut, std::uint32_t block,
                    std::span<RegionMeta> out);

/// Merges every level-0 voxel into the finest entries of `pyramid` (which must match desc) and
/// builds it.
void fill_metadata(const VolumeDesc& desc, const LevelBoxReader& level0, MetadataPyramid& pyramid,
                   std::uint32_t threads);

}  // namespace resoct::detail
