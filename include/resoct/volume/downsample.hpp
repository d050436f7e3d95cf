#pragma once
/// \file
/// Box filtering by 2 along a chosen subset of axes: the one rule that builds every coarser
/// level, whether a source stores its levels or computes them on demand.
///
/// Rule (per coarse voxel): average the fine voxels it covers, accumulated in double. A halved
/// axis of odd extent yields ceil(extent / 2) voxels; the last one averages only the fine voxels
/// that exist (one instead of two along that axis).
/// - u8, u16: round half up of the mean, i.e. floor((sum + n/2) / n) with integer n/2.
/// - f32: NaN voxels are left out of both sum and count, so they do not poison finite
///   neighbours; a coarse voxel whose inputs are all NaN is NaN. +Inf and -Inf take part like any
///   value, so a footprint holding both yields NaN (IEEE: inf - inf).

#include <cstddef>
#include <functional>
#include <span>

#include <glm/vec3.hpp>

#include "resoct/volume/box.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// Extent after one step: ceil(e / 2) on halved axes, unchanged elsewhere.
glm::u64vec3 downsampled_extent(const glm::u64vec3& fine_extent, const glm::bvec3& halve) noexcept;

/// One step over a whole dense buffer (x fastest). `fine` holds fine_extent voxels of type t,
/// `out` downsampled_extent() voxels. Throws Error(invalid_argument) on wrong buffer sizes.
/// Thread-safe (pure function).
void downsample(std::span<const std::byte> fine, const glm::u64vec3& fine_extent,
                const glm::bvec3& halve, VoxelType t, std::span<std::byte> out);

/// Fills `out` (dense, x fastest, box.size() voxels) with the voxels of `box`. The box always
/// lies inside the level it is asked for.
using VoxelBoxReader = std::function<void(const Box3& box, std::span<std::byte> out)>;

/// One step over a region: the coarse voxels of `coarse_box` (which must lie inside
/// downsampled_extent(fine_extent, halve)) computed from the fine voxels that `read_fine`
/// supplies. Only the fine voxels under the box are read. Throws Error(invalid_argument) when the
/// box is empty or outside the coarse level, or `out` has the wrong size.
void downsample_region(const Box3& coarse_box, const glm::u64vec3& fine_extent,
                       const glm::bvec3& halve, VoxelType t, const VoxelBoxReader& read_fine,
                       std::span<std::byte> out);

/// Several steps along a hierarchy: voxels of `box` at level `to` computed from level `from`
/// (<= to) by downsampling through every intermediate level exactly as BrickHierarchy halves
/// axes. `read_from` supplies level-`from` voxels. The result equals downsampling whole levels
/// one after another, restricted to the box. Throws Error(invalid_argument) on bad levels, a box
/// outside level `to` or a wrongly sized `out`.
void downsample_levels(const BrickHierarchy& h, std::uint32_t from, std::uint32_t to,
                       const Box3& box, const VoxelBoxReader& read_from, std::span<std::byte> out);

}  // namespace resoct
