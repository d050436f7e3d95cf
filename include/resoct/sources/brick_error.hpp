#pragma once
/// \file
/// The down-sampling error of a coarse brick, the measure error-bounded level of detail chooses
/// levels by (docs/rendering.md "Error-bounded LOD"; Scene::lod_error_color).
///
/// Definition: the largest |r_l(p) - V0(p)| over the centres p of the level-0 voxels under the
/// brick's core, where V0 is the level-0 voxel and r_l the trilinear reconstruction of level l at
/// p from the padded brick (the reconstruction the kernel samples), divided by the width of the
/// channel's value range. Level 0 has error 0. NaN voxels are ignored.
///
/// The spread (max - min) of the source's region_meta over the core's level-0 box dilated by one
/// level-l voxel bounds the error for every source, since both r_l(p) and V0(p) are averages of
/// level-0 voxels in that box. That bound is answered without reading voxels where it already
/// gives the tightest code (brick_error_code 15; constant regions, empty space give 0), and where
/// the level-0 voxels under the brick exceed `max_level0_voxels`. Elsewhere it is far above the
/// measured error where the data is smooth but not constant, so it is not used.
///
/// Where the error comes from: BrickSource::brick_error() (a store answers from its file, an
/// OME-Zarr or other pyramid source measures once and caches); measure_brick_error() below is
/// the measurement itself.

#include <cstddef>
#include <cstdint>
#include <span>

#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// Level-0 voxels under a brick above which measure_brick_error() bounds instead of measuring: 2^24
/// (a 32³ brick up to level 3; 64 MiB of u32 reads at most).
inline constexpr std::uint64_t kBrickErrorMeasuredVoxels = std::uint64_t(1) << 24;

/// The error of brick `key`, whose padded voxels (as read_brick writes them) are `padded`, in
/// [0, 1] of the channel's value range, or 1 when nothing bounds it (a region without finite
/// values, an empty range). Reads level-0 bricks of `source`; throws what it throws and
/// Error(invalid_argument) naming "padded" for a wrongly sized buffer.
double measure_brick_error(const BrickSource& source, BrickKey key,
                           std::span<const std::byte> padded,
                           std::uint64_t max_level0_voxels = kBrickErrorMeasuredVoxels);

/// The least float >= `error` (a double), so that keeping an error in 4 bytes (HostBrick::error,
/// the brick store's error section) never claims a tighter code than the measurement allows.
/// NaN stays NaN.
float brick_error_to_float(double error) noexcept;

/// The tightest error code, that of an error of at most 2^-15 (RESOCT_PAGE_ERROR_MAX).
inline constexpr std::uint32_t kBrickErrorCodeBest = 15;

/// The page entry's error code of an error in [0, 1] (kernel/page_entry.glsl.h): the largest k
/// in 0..15 with error <= 2^-k; 15 for 0, 0 for errors of 1 or more and for NaN.
std::uint32_t brick_error_code(double error) noexcept;

}  // namespace resoct
