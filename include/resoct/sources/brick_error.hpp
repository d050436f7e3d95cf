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
/// `known_bound` is an upper bound on the error the caller already has (a source's analytic
/// bound, lipschitz_brick_error_bound below): it stands in for the metadata bound where it is
/// tighter, so it is what a brick too large to measure gets, and nothing is read where it
/// already gives the tightest code. The result never exceeds it.
double measure_brick_error(const BrickSource& source, BrickKey key,
                           std::span<const std::byte> padded,
                           std::uint64_t max_level0_voxels = kBrickErrorMeasuredVoxels,
                           double known_bound = 1.0);

/// What an error bound of a coarse brick rests on when the level-0 voxels follow a field
/// known to vary slowly (a procedural source's, or any source that knows a Lipschitz constant).
struct LipschitzErrorTerms {
  /// L: |G(q) - G(p)| <= L |q - p| (Euclidean, level-0 voxel units) for a field G, in stored
  /// value units per level-0 voxel. +infinity when none is known (the bound is then 1).
  double lipschitz = 0.0;
  /// The most any level-0 voxel differs from G at its centre (quantization: 0.5 for integer
  /// types that round).
  double voxel_error = 0.0;
  /// The most any level-l voxel of the brick differs from the exact weighted mean of the
  /// level-0 voxels its recursive box filter covers (downsample.hpp), in stored value units.
  double level_error = 0.0;
};

/// An upper bound on measure_brick_error()'s quantity for brick `key` of hierarchy `h` (range
/// fraction, at most 1), without reading a voxel. Since r_l(p) is a weighted mean of level-0
/// voxels q (trilinear weights on the taps, box-filter weights under each tap), |r_l(p) - V0(p)|
/// <= level_error + 2 voxel_error + L * sqrt(sum over axes of M_a), where M_a is the largest,
/// over the brick's level-0 coordinates p_a, weighted mean of (q_a - p_a)^2: per axis the weights
/// factor, and Jensen's inequality takes the mean distance under the square root. The taps
/// follow the kernel's sampler through the halo exactly as measure_brick_error() does (border
/// voxels repeated). A tap whose footprint is whole along the axis has uniform weights, second
/// moment (f^2 - 1) / 12 + (centre - p)^2; one cut by the volume's end (recursive filter weights
/// not uniform) counts its farthest voxel centre instead. Level 0 gives 0. Throws
/// Error(out_of_range) for a key outside the hierarchy.
double lipschitz_brick_error_bound(const BrickHierarchy& h, BrickKey key,
                                   const LipschitzErrorTerms& terms);

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
