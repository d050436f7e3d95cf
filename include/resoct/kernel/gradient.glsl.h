// resoct kernel: field values at a chosen level without requests, and gradients by finite
// differences (paper 004 §7.1), for shading and isosurface normals.
//
// The gradient of a channel at level l and level-0 position p, in box units of the normalized
// value:
//   central  g_i = (F(c(p + h_i e_i)) − F(c(p − h_i e_i))) / (2 h_i)
//   forward  g_i = (F(c(p + h_i e_i)) − F(p)) / h_i
// F is the level's trilinear field, h_i one level-l voxel along axis i (2^f_i level-0 voxels,
// 2^f_i / voxels_per_box_i box units, so anisotropic spacing is exact), c clamps a position to
// the volume like every sample position. At level 0 this is the clamp-to-edge trilinear field,
// which is what the reference renderer differentiates.
//
// Where the taps come from (the store's halo decides): with a halo of >= 2 voxels every tap of
// a MAPPED brick lies inside that brick's padded voxels, trilinear support included, so all
// taps read the same cache slot. With a halo of 1 a tap outside the brick core looks up its own
// brick at the same level through the page table (seamless across brick borders); when that
// brick is not present the tap reads the central brick (its halo, then clamped), which is
// exact within one voxel of the border and approximate beyond. A halo of 0 is rejected for
// gradient effects by the scene validation (trilinear sampling itself has seams there).
// Gradient taps never request bricks.
//
// At a sample of the march (not an isosurface hit) whose value came from a mapped brick of the
// same level, resoct_source_gradient reads the taps from that brick without a page lookup,
// wherever the six taps' trilinear cells lie inside its padded voxels and no tap is clamped to
// the volume: the halo holds the neighbouring bricks' voxels, so this is the same field the
// lookups above read. Elsewhere (near the padded brick's faces with a halo of 1, at the volume's
// faces, at substitutes) resoct_gradient does the work.
//
// Accessors: as listed in traverse.glsl.h.
#ifndef RESOCT_KERNEL_GRADIENT_GLSL_H
#define RESOCT_KERNEL_GRADIENT_GLSL_H

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/sample.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

/// Clamps a level-0 position into the volume [0, extent), like resoct_clamp_position.
RESOCT_FN void resoct_fx_clamp(RESOCT_IN(ResoctFxParams) p, RESOCT_INOUT(ivec3) cell,
                               RESOCT_INOUT(vec3) frac) {
  ivec3 hi = ivec3(int(p.extent_x) - 1, int(p.extent_y) - 1, int(p.extent_z) - 1);
  for (int a = 0; a < 3; ++a) {
    if (cell[a] < 0) {
      cell[a] = 0;
      frac[a] = 0.0f;
    }
    if (cell[a] > hi[a]) {
      cell[a] = hi[a];
      frac[a] = 0.99999994f;
    }
  }
}

/// Normalized value of a present page entry of brick `brick` at a level-0 position; `fallback`
/// for UNMAPPED.
RESOCT_FN float resoct_entry_normalized(RESOCT_IN(ResoctSampleParams) sp,
                                        RESOCT_IN(ResoctSlotInfo) s, uint entry,
                                        RESOCT_IN(ResoctLevelInfo) L, uvec3 brick, ivec3 cell,
                                        vec3 frac, float fallback) {
  uint state = resoct_page_state(entry);
  if (state == RESOCT_PAGE_STATE_MAPPED) {
    float raw =
        resoct_sample_mapped(entry, L, resoct_frame_brick_size(sp), sp.halo, brick, cell, frac);
    return resoct_normalize_value(raw, s.range_lo, s.inv_range_width);
  }
  if (state == RESOCT_PAGE_STATE_HOMOGENEOUS) return resoct_page_homogeneous_value(entry);
  // EMPTY bricks hold raw zeros.
  if (state == RESOCT_PAGE_STATE_EMPTY) {
    return resoct_normalize_value(0.0f, s.range_lo, s.inv_range_width);
  }
  return fallback;
}

/// Normalized value of a channel at exactly `level` at a level-0 position inside the volume;
/// false when that brick is not present. Never requests.
RESOCT_FN bool resoct_level_value(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctSlotInfo) s,
                                  uint level, ivec3 cell, vec3 frac, RESOCT_OUT(float) value) {
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(level);
  uvec3 b = resoct_brick_at(L, resoct_frame_brick_size(sp), cell);
  uint e = resoct_page_entry_of(s.slot, level, sp.level_count, L, b);
  value = 0.0f;
  if (resoct_page_state(e) == RESOCT_PAGE_STATE_UNMAPPED) return false;
  value = resoct_entry_normalized(sp, s, e, L, b, cell, frac, 0.0f);
  return true;
}

/// The level resoct_residency_channel samples at a position (the target if present, else the
/// nearest partially resident one, coarser first): gradients and isosurface refinement use the
/// level the value came from. The target when no level is present.
RESOCT_FN uint resoct_present_level(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctSlotInfo) s,
                                    uint node, uint target, ivec3 cell) {
  uvec3 bs = resoct_frame_brick_size(sp);
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(target);
  uint e = resoct_page_entry_of(s.slot, target, sp.level_count, L, resoct_brick_at(L, bs, cell));
  if (resoct_page_state(e) != RESOCT_PAGE_STATE_UNMAPPED) return target;
  uint r =
      resoct_read_node(resoct_node_base(node, s.slot, sp.node_slot_count) + RESOCT_NODE_RESIDENCY) &
      resoct_allowed_levels(s);
  int l = resoct_node_next_coarser(r, target);
  for (uint pass = 0u; pass < 2u; ++pass) {
    while (l >= 0) {
      uint lu = uint(l);
      RESOCT_IN(ResoctLevelInfo) Lc = resoct_read_level(lu);
      uint ec = resoct_page_entry_of(s.slot, lu, sp.level_count, Lc, resoct_brick_at(Lc, bs, cell));
      if (resoct_page_state(ec) != RESOCT_PAGE_STATE_UNMAPPED) return lu;
      l = pass == 0u ? resoct_node_next_coarser(r, lu) : resoct_node_next_finer(r, lu);
    }
    l = resoct_node_next_finer(r, target);
  }
  return target;
}

/// The level the standard-octree mode samples at a position (resoct_octree_channel): the finest
/// present level above the first missing one, walking down from the coarsest to the target.
RESOCT_FN uint resoct_octree_level(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctSlotInfo) s,
                                   uint target, ivec3 cell) {
  uvec3 bs = resoct_frame_brick_size(sp);
  uint best = target;
  uint l = s.coarsest_level + 1u;
  while (l > target) {
    l = l - 1u;
    RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(l);
    uint state = resoct_page_state(
        resoct_page_entry_of(s.slot, l, sp.level_count, L, resoct_brick_at(L, bs, cell)));
    if (state == RESOCT_PAGE_STATE_UNMAPPED) break;
    best = l;
    if (state == RESOCT_PAGE_STATE_EMPTY) break;
  }
  return best;
}

/// One gradient tap: the central brick when `same_brick`, else the tap's own brick if present,
/// else the central brick; `fallback` when neither is present.
RESOCT_FN float resoct_gradient_tap(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctSlotInfo) s,
                                    uint level, RESOCT_IN(ResoctLevelInfo) L, uint e0, uvec3 b0,
                                    bool same_brick, ivec3 cell, vec3 frac, float fallback) {
  uint e = e0;
  uvec3 b = b0;
  if (!same_brick) {
    uvec3 bn = resoct_brick_at(L, resoct_frame_brick_size(sp), cell);
    if (any(notEqual(bn, b0))) {
      uint en = resoct_page_entry_of(s.slot, level, sp.level_count, L, bn);
      if (resoct_page_state(en) != RESOCT_PAGE_STATE_UNMAPPED) {
        e = en;
        b = bn;
      }
    }
  }
  return resoct_entry_normalized(sp, s, e, L, b, cell, frac, fallback);
}

#ifndef RESOCT_SAMPLE_CACHE_TAPS
/// Raw values of a cache slot's padded brick at `pos` plus (and, when `central`, minus) one voxel
/// along each axis: the gradient taps of a sample. A backend may define RESOCT_SAMPLE_CACHE_TAPS
/// before including the kernel to compute the six lookups together (the CPU backend shares their
/// cell weights); this is the portable version.
RESOCT_FN void resoct_sample_cache_taps(uint cache_slot, vec3 pos, bool central,
                                        RESOCT_OUT(vec3) plus, RESOCT_OUT(vec3) minus) {
  plus = vec3(0.0f);
  minus = vec3(0.0f);
  for (int a = 0; a < 3; ++a) {
    vec3 q = pos;
    q[a] = pos[a] + 1.0f;
    plus[a] = resoct_sample_cache(cache_slot, q);
    if (central) {
      q[a] = pos[a] - 1.0f;
      minus[a] = resoct_sample_cache(cache_slot, q);
    }
  }
}
#define RESOCT_SAMPLE_CACHE_TAPS resoct_sample_cache_taps
#endif

/// resoct_gradient at a sample of the march whose value came from the mapped source `src` (at
/// ray parameter t, level-0 cell `cell`), without a page lookup: the taps, one voxel of the
/// source's level from the sample's padded position, are read from the source's brick wherever
/// their trilinear cells lie inside its padded voxels (the halo holds the neighbouring bricks'
/// voxels, so this is the field resoct_gradient reads through the page table). False, leaving the
/// work to resoct_gradient, where a tap would leave the padded brick or be clamped to the
/// volume. The taps' positions round like the sample's (affine in t) rather than like
/// resoct_gradient's (from the cell): the results differ in the last bits.
RESOCT_FN bool resoct_source_gradient(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                                      RESOCT_IN(ResoctSource) src, float t, ivec3 cell,
                                      float center, RESOCT_OUT(vec3) g) {
  g = vec3(0.0f);
  if (src.kind != RESOCT_CH_VALUE || src.cache_slot == RESOCT_SOURCE_NO_SLOT) return false;
  ivec3 h = ivec3(uvec3(1u) << resoct_level_factor(resoct_read_level(src.level)));
  bool central = p.gradient_forward == 0u;
  ivec3 hi = ivec3(int(p.extent_x) - 1, int(p.extent_y) - 1, int(p.extent_z) - 1);
  for (int a = 0; a < 3; ++a) {
    if (cell[a] > hi[a] - h[a] || (central && cell[a] < h[a])) return false;
  }
  vec3 pos = src.ray_base + t * src.ray_dir;
  // Trilinear cell coordinates of the taps, unclamped in [0, padded - 1].
  vec3 c = pos - vec3(0.5f);
  vec3 last = vec3(resoct_frame_brick_size(sp) + uvec3(2u * sp.halo)) - vec3(1.0f);
  if (any(lessThan(c, vec3(central ? 1.0f : 0.0f))) || any(greaterThan(c + vec3(1.0f), last))) {
    return false;
  }
  vec3 plus;
  vec3 minus;
  RESOCT_SAMPLE_CACHE_TAPS(src.cache_slot, pos, central, plus, minus);
  vec3 box_h = vec3(h) / resoct_fx_voxels_per_box(p);
  vec3 vp = (plus - vec3(src.range_lo)) * src.inv_range_width;
  if (central) {
    vec3 vm = (minus - vec3(src.range_lo)) * src.inv_range_width;
    g = (vp - vm) / (2.0f * box_h);
  } else {
    g = (vp - vec3(center)) / box_h;
  }
  return true;
}

/// Box-space gradient of the normalized field of slot `s` at `level` (see the file comment).
/// `center` is the value at the position, used only when no brick of the level is present.
RESOCT_FN vec3 resoct_gradient(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                               RESOCT_IN(ResoctSlotInfo) s, uint level, ivec3 cell, vec3 frac,
                               float center) {
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(level);
  uvec3 b0 = resoct_brick_at(L, resoct_frame_brick_size(sp), cell);
  uint e0 = resoct_page_entry_of(s.slot, level, sp.level_count, L, b0);
  bool same = sp.halo >= 2u && resoct_page_state(e0) == RESOCT_PAGE_STATE_MAPPED;
  ivec3 h = ivec3(uvec3(1u) << resoct_level_factor(L));
  vec3 box_h = vec3(h) / resoct_fx_voxels_per_box(p);
  float f0 = center;
  if (p.gradient_forward != 0u) {
    f0 = resoct_gradient_tap(sp, s, level, L, e0, b0, true, cell, frac, center);
  }
  vec3 g = vec3(0.0f);
  for (int a = 0; a < 3; ++a) {
    ivec3 cp = cell;
    vec3 fp = frac;
    cp[a] = cp[a] + h[a];
    resoct_fx_clamp(p, cp, fp);
    float vp = resoct_gradient_tap(sp, s, level, L, e0, b0, same, cp, fp, center);
    if (p.gradient_forward != 0u) {
      g[a] = (vp - f0) / box_h[a];
    } else {
      ivec3 cm = cell;
      vec3 fm = frac;
      cm[a] = cm[a] - h[a];
      resoct_fx_clamp(p, cm, fm);
      float vm = resoct_gradient_tap(sp, s, level, L, e0, b0, same, cm, fm, center);
      g[a] = (vp - vm) / (2.0f * box_h[a]);
    }
  }
  return g;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_GRADIENT_GLSL_H
