// resoct kernel: ray/box entry and exit, robust for axis-parallel rays, and node-local coordinates.
//
// Convention: boxes are HALF-OPEN, [lo, hi) per axis, like voxels, bricks and octree nodes, so
// every point belongs to exactly one cell. A ray whose direction component along an axis is zero
// (or |d| < RESOCT_RAY_PARALLEL_EPS, which also covers -0.0 and denormals flushed to zero) never
// crosses that axis' slabs: it is inside for all t when lo <= origin < hi and misses otherwise.
// Such components get a reciprocal of 0 (resoct_ray_inverse) and are never multiplied, so no
// 0/0 or 0*inf NaN can appear. A ray lying exactly on the lower face of a box is inside it; one
// lying on the upper face is outside (it belongs to the neighbour). The result is vec2(t_enter,
// t_exit); the ray hits iff t_enter < t_exit, and the samples it owns are t_enter <= t < t_exit.
// Rays that only touch an edge or corner get an empty interval. Unbounded ends are
// +-RESOCT_RAY_T_INF (a finite float, since GLSL has no literal for infinity); callers clamp
// t_enter to their own t_min (e.g. 0 for the camera origin).
//
// Precision for huge volumes (an axis of 2^20 voxels): a float holds a normalized position only
// to about 2^-24, i.e. a sixteenth of a voxel there, and a float level-0 voxel coordinate near
// 2^20 only to 1/8 voxel. Callers therefore never intersect nodes in global float coordinates.
// They keep the ray position as an integer level-0 voxel (ivec3, exact) plus a float fraction,
// subtract the node's integer lower corner in integers (resoct_relative_origin), and intersect in
// node-local coordinates where the box is [0, node_size). The float error is then relative to the
// distance between the sample and the node, not to the volume size.
#ifndef RESOCT_KERNEL_RAY_GLSL_H
#define RESOCT_KERNEL_RAY_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

/// Stand-in for infinity in ray parameters (largest useful float order of magnitude).
RESOCT_CONST(float, RESOCT_RAY_T_INF, 3.0e38f);
/// Direction components smaller than this in magnitude count as parallel to the slab. A ray of
/// unit length with such a component would need t > 1e20 to cross a unit slab.
RESOCT_CONST(float, RESOCT_RAY_PARALLEL_EPS, 1.0e-20f);

/// Per-ray reciprocal of a direction component: 1 / d, or 0 where the ray is parallel to the
/// axis (|d| < RESOCT_RAY_PARALLEL_EPS; 1 / d is never 0 for a finite d, so 0 marks parallel).
/// Computed once per ray, so that every slab test after it multiplies instead of dividing. Both
/// backends then round alike: a device compiler may lower a division x / d to x * rcp(d), which
/// can differ from the host's quotient in the last bit, while 1 / d and a product are correctly
/// rounded on both.
RESOCT_FN float resoct_ray_inverse1(float d) {
  return abs(d) < RESOCT_RAY_PARALLEL_EPS ? 0.0f : 1.0f / d;
}

/// resoct_ray_inverse1 per component: the ray's reciprocal direction.
RESOCT_FN vec3 resoct_ray_inverse(vec3 dir) {
  return vec3(resoct_ray_inverse1(dir.x), resoct_ray_inverse1(dir.y), resoct_ray_inverse1(dir.z));
}

/// Slab interval of one axis: (t at which the ray enters, t at which it leaves) [lo, hi), for the
/// reciprocal direction component `inv` (resoct_ray_inverse1).
RESOCT_FN vec2 resoct_ray_slab(float origin, float inv, float lo, float hi) {
  if (inv == 0.0f) {
    // Parallel: inside for all t or never. Half-open: the lower face belongs to the box.
    if (origin >= lo && origin < hi) return vec2(-RESOCT_RAY_T_INF, RESOCT_RAY_T_INF);
    return vec2(RESOCT_RAY_T_INF, -RESOCT_RAY_T_INF);
  }
  float t0 = (lo - origin) * inv;
  float t1 = (hi - origin) * inv;
  return vec2(min(t0, t1), max(t0, t1));
}

/// The exit of resoct_ray_slab alone, the same float: only the far face's product is taken (the
/// max of the two products is the far face's, as rounding is monotonic).
RESOCT_FN float resoct_ray_slab_exit(float origin, float inv, float lo, float hi) {
  if (inv == 0.0f) return origin >= lo && origin < hi ? RESOCT_RAY_T_INF : -RESOCT_RAY_T_INF;
  return ((inv > 0.0f ? hi : lo) - origin) * inv;
}

/// Entry and exit parameters of the ray origin + t * dir with the half-open box [lo, hi), for the
/// ray's reciprocal direction `inv` (resoct_ray_inverse). Hit iff result.x < result.y. Never NaN
/// for finite inputs.
RESOCT_FN vec2 resoct_ray_box_inv(vec3 origin, vec3 inv, vec3 lo, vec3 hi) {
  vec2 sx = resoct_ray_slab(origin.x, inv.x, lo.x, hi.x);
  vec2 sy = resoct_ray_slab(origin.y, inv.y, lo.y, hi.y);
  vec2 sz = resoct_ray_slab(origin.z, inv.z, lo.z, hi.z);
  return vec2(max(sx.x, max(sy.x, sz.x)), min(sx.y, min(sy.y, sz.y)));
}

/// The exit of resoct_ray_box_inv alone (resoct_ray_box_inv(...).y, the same float).
RESOCT_FN float resoct_ray_box_exit_inv(vec3 origin, vec3 inv, vec3 lo, vec3 hi) {
  return min(resoct_ray_slab_exit(origin.x, inv.x, lo.x, hi.x),
             min(resoct_ray_slab_exit(origin.y, inv.y, lo.y, hi.y),
                 resoct_ray_slab_exit(origin.z, inv.z, lo.z, hi.z)));
}

/// resoct_ray_box_inv for a direction `dir` (its reciprocal taken here): for one-off tests; a
/// march takes the reciprocal once per ray.
RESOCT_FN vec2 resoct_ray_box(vec3 origin, vec3 dir, vec3 lo, vec3 hi) {
  return resoct_ray_box_inv(origin, resoct_ray_inverse(dir), lo, hi);
}

/// True when an interval from resoct_ray_box is non-empty after clamping its start to t_min.
RESOCT_FN bool resoct_ray_hits(vec2 interval, float t_min) {
  return max(interval.x, t_min) < interval.y;
}

/// a - b as a float, rounded once, for any two ints. The difference is taken in unsigned
/// arithmetic: a signed a - b overflows when the box is unclipped (a corner of -(2^31 - 1),
/// traverse.glsl.h), which is undefined behaviour in C++ and wraps to the wrong sign in GLSL.
/// Where a - b fits an int the result equals float(a - b), bit for bit (rounding is symmetric).
/// C++ takes the exact difference in 64 bits and rounds it once, the same float without the
/// branch (three per box test, the hottest line of the decisions in callgrind).
RESOCT_FN float resoct_int_difference(int a, int b) {
#ifdef __cplusplus
  return float(std::int64_t(a) - std::int64_t(b));
#else
  return a >= b ? float(uint(a) - uint(b)) : -float(uint(b) - uint(a));
#endif
}

/// Ray origin relative to a node's lower corner, in level-0 voxels. The origin is given split
/// into an exact integer voxel `origin_cell` and a fraction `origin_frac` (any float, normally in
/// [0, 1)); the integer subtraction is exact for any volume below 2^31 voxels per axis.
RESOCT_FN vec3 resoct_relative_origin(ivec3 origin_cell, vec3 origin_frac, ivec3 node_lo) {
  return vec3(resoct_int_difference(origin_cell.x, node_lo.x),
              resoct_int_difference(origin_cell.y, node_lo.y),
              resoct_int_difference(origin_cell.z, node_lo.z)) +
         origin_frac;
}

/// Entry and exit with a node in node-local coordinates: the node is [0, node_size) and the
/// origin is relative to its lower corner (see resoct_relative_origin). t is in the units of the
/// direction whose reciprocal is `inv` (resoct_ray_inverse); use a direction in level-0 voxels
/// per unit t so that t matches the caller's ray.
RESOCT_FN vec2 resoct_ray_node_local(vec3 origin_rel, vec3 inv, vec3 node_size) {
  return resoct_ray_box_inv(origin_rel, inv, vec3(0.0f), node_size);
}

/// Moves the integer/fraction split so that the fraction is in [0, 1) again, keeping
/// cell + frac unchanged up to float rounding of the fraction.
RESOCT_FN void resoct_split_normalize(RESOCT_INOUT(ivec3) cell, RESOCT_INOUT(vec3) frac) {
  vec3 whole = resoct_floor(frac);
  cell = cell + ivec3(whole);
  frac = frac - whole;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_RAY_GLSL_H
