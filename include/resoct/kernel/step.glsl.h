// resoct kernel: sampling step along a ray and per-sample level of detail.
//
// Units: everything is in the normalized physical box (min corner at the origin, the longest
// physical axis spans [0, 1]); see docs/rendering.md for the derivations.
//
// Step (thesis Eq. 8.2-8.3, generalised): with h_i the voxel size along axis i of the finest
// level any visible channel may use, a step dt along the unit direction d advances |d_i| dt along
// axis i, so one voxel per axis is reached at dt_i = h_i / |d_i| (Eq. 8.2 with v_i s_i read as
// voxels per box unit, 1 / h_i). dt = max(min_i dt_i * step_scale, min_step) (Eq. 8.3 plus a
// floor). Components with |d_i| < RESOCT_RAY_PARALLEL_EPS impose no limit; a zero direction
// falls back to the smallest h_i. resoct_advance_t guarantees t strictly increases even where
// t + dt rounds back to t. Segments [t, t + dt) are cut at the exit (resoct_segment_length) and
// sampled at their midpoints.
//
// Level of detail: a pixel's world footprint at view depth z is footprint_base +
// footprint_slope * z (orthographic: base = view height / pixel rows, slope = 0; perspective:
// base = 0, slope = 2 tan(fov / 2) / pixel rows). A level is acceptable while its LARGEST voxel
// dimension is at most lod_error_px footprints, so no voxel of the chosen level covers more than
// lod_error_px pixels in any view direction (paper 002: pixel error <= 1; paper 004: dP/dV). The
// target is the coarsest acceptable level, clamped per channel to [finest, coarsest].
//
// Accessor the including file must define BEFORE including this header (C++: in namespace
// resoct::kernel or globally; GLSL: at global scope):
//   float resoct_read_level_size_log2(uint level)
//     log2 of the largest voxel dimension of `level` in box units, non-decreasing in level.
#ifndef RESOCT_KERNEL_STEP_GLSL_H
#define RESOCT_KERNEL_STEP_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/ray.glsl.h"

RESOCT_KERNEL_BEGIN

/// 2^-23: |t| * this is at least one float ulp of t.
RESOCT_CONST(float, RESOCT_T_ULP_FACTOR, 1.1920929e-7f);
/// Smallest advance of t at t = 0 (where the relative ulp bound is 0).
RESOCT_CONST(float, RESOCT_T_MIN_ADVANCE, 1.0e-30f);
/// Smallest footprint used for the LOD logarithm, so log2 never sees 0.
RESOCT_CONST(float, RESOCT_LOD_MIN_FOOTPRINT, 1.0e-30f);

/// Step length along the unit direction `dir` for voxel sizes `voxel_size` (box units per voxel,
/// per axis, of the finest visible level), Eq. 8.2-8.3 with zero guards and a floor `min_step`.
RESOCT_FN float resoct_step_size(vec3 dir, vec3 voxel_size, float step_scale, float min_step) {
  vec3 ad = abs(dir);
  float dt = RESOCT_RAY_T_INF;
  // Products with correctly rounded reciprocals, not quotients: a device may divide as
  // x * rcp(y), and the step must be the same float on every backend (kernel/ray.glsl.h).
  if (ad.x >= RESOCT_RAY_PARALLEL_EPS) dt = min(dt, voxel_size.x * (1.0f / ad.x));
  if (ad.y >= RESOCT_RAY_PARALLEL_EPS) dt = min(dt, voxel_size.y * (1.0f / ad.y));
  if (ad.z >= RESOCT_RAY_PARALLEL_EPS) dt = min(dt, voxel_size.z * (1.0f / ad.z));
  if (dt >= RESOCT_RAY_T_INF) dt = min(voxel_size.x, min(voxel_size.y, voxel_size.z));
  return max(dt * step_scale, min_step);
}

/// t + dt, but at least the next float after t, so every loop iteration makes progress.
RESOCT_FN float resoct_advance_t(float t, float dt) {
  float next = t + dt;
  if (next <= t) next = t + max(abs(t) * RESOCT_T_ULP_FACTOR, RESOCT_T_MIN_ADVANCE);
  return next;
}

/// The start of step j of a march whose step grid starts at t_grid: t_grid + j * dt, each
/// operation rounded once (precise: no fused multiply-add on a device), so a sample's position
/// depends on its index alone and never on how the march reached it: one skip of k steps and k
/// single steps land on the same t, whichever nodes the skips were computed from. `t` is the
/// current step's start; where dt is below its ulp the result is resoct_advance_t(t, dt), so
/// every iteration still makes progress. j is exact up to 2^24 (far above any iteration cap).
RESOCT_FN float resoct_grid_t(float t_grid, uint j, float dt, float t) {
  RESOCT_PRECISE float jdt = float(j) * dt;
  RESOCT_PRECISE float next = t_grid + jdt;
  if (next <= t) next = resoct_advance_t(t, dt);
  return next;
}

/// A segment's length in units of the reference step Δ₀ (the opacity correction's exponent), as
/// a product with the correctly rounded reciprocal: a device may divide as x * rcp(y), and the
/// ratio decides early termination, so it must be the same float on every backend.
RESOCT_FN float resoct_step_ratio(float seg, float ref_step) {
  return seg * (1.0f / ref_step);
}

/// Length of the segment that starts at t: the step, shortened at the exit so that segments tile
/// [t_enter, t_exit) and the last sample's opacity is corrected for its true length. Sample at
/// the segment's midpoint; 0 once t >= t_exit.
/// Fraction of a step below which the rest of a ray inside the volume is not sampled.
RESOCT_CONST(float, RESOCT_SEGMENT_EPS, 1.0e-4f);

RESOCT_FN float resoct_segment_length(float t, float dt, float t_exit) {
  return max(min(dt, t_exit - t), 0.0f);
}

/// World size of one pixel at view depth `depth` (distance along the camera's forward axis).
RESOCT_FN float resoct_pixel_footprint(float footprint_base, float footprint_slope, float depth) {
  return footprint_base + footprint_slope * max(depth, 0.0f);
}

/// log2 of the largest voxel dimension the target level may have at view depth `depth`.
RESOCT_FN float resoct_lod_budget_log2(float footprint_base, float footprint_slope, float depth,
                                       float lod_error_px) {
  float allowed = resoct_pixel_footprint(footprint_base, footprint_slope, depth) * lod_error_px;
  return log2(max(allowed, RESOCT_LOD_MIN_FOOTPRINT));
}

/// Coarsest level in [0, level_count) whose largest voxel dimension fits the budget; 0 (the
/// finest) when none does. Monotone in the budget because level sizes are non-decreasing.
RESOCT_FN uint resoct_lod_level(float budget_log2, uint level_count) {
  uint level = 0u;
  for (uint l = 1u; l < level_count; ++l) {
    if (resoct_read_level_size_log2(l) > budget_log2) break;
    level = l;
  }
  return level;
}

/// The ray parameter from which resoct_lod_level can pick a level coarser than `lod`, for a ray
/// whose view depth grows by `depth_per_t` per unit t (resoct_view_depth at t = 1); infinite
/// when it never does (orthographic views, the coarsest level). A segment ends there, and the
/// next sample chooses its level anew.
RESOCT_FN float resoct_lod_change_t(float footprint_base, float footprint_slope, float depth_per_t,
                                    float lod_error_px, uint lod, uint level_count) {
  if (lod + 1u >= level_count || !(footprint_slope * depth_per_t * lod_error_px > 0.0f)) {
    return RESOCT_RAY_T_INF;
  }
  RESOCT_PRECISE float footprint = exp2(resoct_read_level_size_log2(lod + 1u)) / lod_error_px;
  RESOCT_PRECISE float depth = (footprint - footprint_base) / footprint_slope;
  return depth / depth_per_t;
}

/// A channel's target level: the shared LOD level clamped to its allowed [finest, coarsest].
RESOCT_FN uint resoct_channel_level(uint lod_level, uint finest, uint coarsest) {
  return min(max(lod_level, finest), max(finest, coarsest));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_STEP_GLSL_H
