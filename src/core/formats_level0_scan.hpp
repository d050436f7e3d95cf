#pragma once
// Whole-level-0 passes of PyramidSource (internal): value ranges and the metadata pyramid, read
// tile by tile through a LevelBoxReader on several threads.

#include <cstdint>
#include <utility>
#include <vector>

#include "resoct/formats/pyramid_source.hpp"

namespace resoct::detail {

/// Finite (min, max) of every channel's level-0 voxels; (+inf, -inf) for a channel without any.
std::vector<std::pair<double, double>> scan_finite_minmax(const VolumeDesc& desc,
                                                          const LevelBoxReader& level0,
                                                          std::uint32_t threads);

/// Merges every level-0 voxel into the finest entries of `pyramid` (which must match desc) and
/// builds it.
void fill_metadata(const VolumeDesc& desc, const LevelBoxReader& level0, MetadataPyramid& pyramid,
                   std::uint32_t threads);

}  // namespace resoct::detail
