#pragma once
/// \file
/// Exact culling records of the residency octree's leaves, computed from the voxels of a level-0
/// brick (docs/residency-octree.md §4). A pure function of the brick, the octree layout and the
/// channel's value range, so the brick loader computes it on its own threads beside scan_brick,
/// and the frame thread only stores the result (ResidencyOctree::leaf_scans_arrived).

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/engine/octree_layout.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/volume/box.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// Min, max and occupancy bins of the finite voxels in a box of a padded brick (min > max when
/// there is none). NaN is skipped.
struct VoxelBoxScan {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  std::uint32_t occupancy = 0;
};

/// Scans `box` (level voxels) of a padded brick whose first voxel is `padded_lo` and whose size is
/// `padded_dim`; `box` must lie inside it. Each row's min and max come first (a loop the compiler
/// vectorizes); occupancy bins are monotonic in the value, so only rows whose extremes fall in
/// different bins pay per-voxel bins.
VoxelBoxScan scan_voxel_box(std::span<const std::byte> voxels, VoxelType type,
                            const glm::i64vec3& padded_lo, const glm::i64vec3& padded_dim,
                            const Box3& box, const ValueRange& range);

/// One leaf's record: the min/max word (octree_pack_range over the channel's range; 0 when the
/// support holds no finite value) and the 32 occupancy bins of its sampling support's voxels.
struct LeafScan {
  std::uint64_t leaf = 0;  ///< flat node index (OctreeLayout)
  std::uint32_t minmax = 0;
  std::uint32_t occupancy = 0;
  bool operator==(const LeafScan&) const = default;
};

/// The leaves a level-0 brick settles exactly: those fully inside its core box whose sampling
/// support (OctreeLayout::sampling_support) the padded brick holds, i.e. all of them when the
/// halo is at least one voxel, none with halo 0. Calls `f(leaf, support)` for each.
/// Throws Error(out_of_range) for a brick outside level 0.
void for_each_exact_leaf(const OctreeLayout& layout, const BrickHierarchy& hierarchy,
                         glm::uvec3 brick,
                         const std::function<void(std::uint64_t leaf, const Box3& support)>& f);

/// The records of the leaves for_each_exact_leaf visits, scanned from `voxels` (padded, of the
/// volume's type, as BrickSource::read_brick writes them), in visiting order (scan_voxel_box over
/// each support).
/// Throws Error naming "voxels" for a wrong buffer size, or Error(out_of_range).
std::vector<LeafScan> scan_leaves(const OctreeLayout& layout, const BrickHierarchy& hierarchy,
                                  const ValueRange& range, glm::uvec3 brick,
                                  std::span<const std::byte> voxels);

/// The same for a constant brick (BrickMeta::constant over its padded voxels): every leaf gets
/// the record of the one value (min > max: no finite value, an empty record).
/// Throws Error naming "meta" when the brick is not constant, or Error(out_of_range).
std::vector<LeafScan> scan_constant_leaves(const OctreeLayout& layout,
                                           const BrickHierarchy& hierarchy, const ValueRange& range,
                                           glm::uvec3 brick, const BrickMeta& meta);

}  // namespace resoct
