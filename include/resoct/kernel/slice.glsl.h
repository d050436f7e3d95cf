// resoct kernel: slice planes, rendered through the same page table, level choice and request
// machinery as the volume. See docs/rendering.md ("Slices and lens").
//
// A ray meets plane i at one parameter t (kept when it lies inside the volume interval). There
// the plane's pixel footprint picks the level: the view-depth footprint divided by |cos θ|
// between ray and plane normal (an oblique plane stretches a pixel over more voxels; the factor
// is capped at RESOCT_SLICE_MAX_STRETCH), against the same per-level size table as the volume.
// Each shown channel takes its target level when present, else requests it (with the frame's
// request strategy) and substitutes the nearest present level of its range, coarser first, then
// finer. An EMPTY brick is all zero, so on a slice it shows value 0. With window/level the
// channel is the opaque grey clamp((v - level) / window + 1/2, 0, 1), else the transfer
// function's colour and alpha as they are (a plane has no thickness to correct for). Channels
// are intermixed like volume samples (composite.glsl.h) and the result composited at t: what
// lies in front covers the slice, the slice covers what lies behind.
//
// Accessors: as listed in traverse.glsl.h.
#ifndef RESOCT_KERNEL_SLICE_GLSL_H
#define RESOCT_KERNEL_SLICE_GLSL_H

#include "resoct/kernel/camera_ray.glsl.h"
#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/sample.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/tf.glsl.h"

// Read-only frame parameter: by reference in C++ (no 400-byte copy per call), by value in GLSL.
#ifndef RESOCT_FRAME_IN
#ifdef __cplusplus
#define RESOCT_FRAME_IN const ResoctFrame&
#else
#define RESOCT_FRAME_IN ResoctFrame
#endif
#endif

RESOCT_KERNEL_BEGIN

/// Largest footprint stretch 1 / |cos θ| of a grazing plane (beyond it the plane is edge-on).
RESOCT_CONST(float, RESOCT_SLICE_MAX_STRETCH, 64.0f);

RESOCT_FN vec3 resoct_slice_normal(RESOCT_FRAME_IN f, uint i) {
  return vec3(f.slice_normal[3u * i], f.slice_normal[3u * i + 1u], f.slice_normal[3u * i + 2u]);
}

/// Parameter at which the ray origin_cell + origin_frac + t * dir_vox meets plane i;
/// RESOCT_RAY_T_INF when it runs parallel to it.
RESOCT_FN float resoct_slice_hit(RESOCT_FRAME_IN f, uint i, ivec3 origin_cell, vec3 origin_frac,
                                 vec3 dir_vox) {
  vec3 n = resoct_slice_normal(f, i);
  ivec3 cell = ivec3(f.slice_cell[3u * i], f.slice_cell[3u * i + 1u], f.slice_cell[3u * i + 2u]);
  vec3 rel = vec3(cell - origin_cell) +
             (vec3(f.slice_frac[3u * i], f.slice_frac[3u * i + 1u], f.slice_frac[3u * i + 2u]) -
              origin_frac);
  float denom = dot(n, dir_vox);
  if (abs(denom) < RESOCT_RAY_PARALLEL_EPS) return RESOCT_RAY_T_INF;
  return dot(n, rel) / denom;
}

/// Level of detail on plane i at parameter t: the view-depth footprint stretched by the plane's
/// obliquity.
RESOCT_FN uint resoct_slice_lod(RESOCT_FRAME_IN f, uint i, vec3 dir_box, float t) {
  vec3 nb = normalize(resoct_slice_normal(f, i) * resoct_frame_voxels_per_box(f));
  float cosine = abs(dot(nb, dir_box));
  float stretch = 1.0f / max(cosine, 1.0f / RESOCT_SLICE_MAX_STRETCH);
  float fp =
      resoct_pixel_footprint(f.footprint_base, f.footprint_slope, resoct_view_depth(f, dir_box, t));
  float budget = log2(max(fp * stretch * f.lod_error_px, RESOCT_LOD_MIN_FOOTPRINT));
  return resoct_lod_level(budget, f.level_count);
}

/// Value of a present page entry on a slice: EMPTY is value 0.
RESOCT_FN bool resoct_slice_entry(ResoctSlotInfo s, uint entry, ResoctLevelInfo L, uvec3 bs,
                                  uint halo, uvec3 brick, ivec3 cell, vec3 frac,
                                  RESOCT_OUT(float) value, RESOCT_INOUT(ResoctRayStats) st) {
  return resoct_entry_value(s, entry, L, bs, halo, brick, cell, frac, value, st) != RESOCT_CH_NONE;
}

/// One channel on a slice: the target level if present, else request it and substitute the
/// nearest present level in [finest, coarsest], coarser first. False when none is present.
RESOCT_FN bool resoct_slice_channel(ResoctSampleParams p, ResoctSlotInfo s, uint target, ivec3 cell,
                                    vec3 frac, RESOCT_INOUT(uint) last_key, RESOCT_OUT(float) value,
                                    RESOCT_INOUT(ResoctRayStats) st) {
  value = 0.0f;
  uvec3 bs = resoct_frame_brick_size(p);
  ResoctLevelInfo L = resoct_read_level(target);
  uvec3 b = resoct_brick_at(L, bs, cell);
  uint e = resoct_page_entry_of(s.slot, target, p.level_count, L, b);
  if (resoct_page_state(e) != RESOCT_PAGE_STATE_UNMAPPED) {
    return resoct_slice_entry(s, e, L, bs, p.halo, b, cell, frac, value, st);
  }
  resoct_request_missing(p, s, target, cell, last_key, st);
  for (uint l = target + 1u; l <= s.coarsest_level; ++l) {
    ResoctLevelInfo Lc = resoct_read_level(l);
    uvec3 bc = resoct_brick_at(Lc, bs, cell);
    uint ec = resoct_page_entry_of(s.slot, l, p.level_count, Lc, bc);
    if (resoct_page_state(ec) != RESOCT_PAGE_STATE_UNMAPPED) {
      return resoct_slice_entry(s, ec, Lc, bs, p.halo, bc, cell, frac, value, st);
    }
  }
  uint l = target;
  while (l > s.finest_level) {
    l = l - 1u;
    ResoctLevelInfo Lf = resoct_read_level(l);
    uvec3 bf = resoct_brick_at(Lf, bs, cell);
    uint ef = resoct_page_entry_of(s.slot, l, p.level_count, Lf, bf);
    if (resoct_page_state(ef) != RESOCT_PAGE_STATE_UNMAPPED) {
      return resoct_slice_entry(s, ef, Lf, bs, p.halo, bf, cell, frac, value, st);
    }
  }
  return false;
}

/// Premultiplied colour of plane i where the ray meets it at t (inside the volume).
RESOCT_FN vec4 resoct_slice_shade(RESOCT_FRAME_IN f, uint i, ivec3 origin_cell, vec3 origin_frac,
                                  vec3 dir_box, vec3 dir_vox, float t,
                                  RESOCT_INOUT(ResoctRayStats) st) {
  ivec3 cell;
  vec3 frac;
  resoct_ray_position(origin_cell, origin_frac, dir_vox, t, cell, frac);
  resoct_clamp_position(f, cell, frac);
  uint lod = resoct_slice_lod(f, i, dir_box, t);
  ResoctSampleParams p = resoct_sample_params(f);
  vec4 weighted;
  float combined;
  resoct_mix_begin(weighted, combined);
  bool any_value = false;
  uint mask = f.slice_channels[i];
  uint n = min(f.slot_count, RESOCT_MAX_SLOTS);
  for (uint c = 0u; c < n; ++c) {
    if (((mask >> c) & 1u) == 0u) continue;
    ResoctSlotInfo s = resoct_read_slot(c);
    uint last_key = RESOCT_REQUEST_KEY_NONE;
    float value;
    uint target = resoct_channel_level(lod, s.finest_level, s.coarsest_level);
    if (!resoct_slice_channel(p, s, target, cell, frac, last_key, value, st)) continue;
    any_value = true;
    if (f.slice_window[i] > 0.0f) {
      float g = clamp((value - f.slice_level[i]) / f.slice_window[i] + 0.5f, 0.0f, 1.0f);
      resoct_mix_add(weighted, combined, vec3(g), 1.0f);
    } else {
      vec4 rgba = resoct_tf_lookup(s.slot, value);
      resoct_mix_add(weighted, combined, vec3(rgba.r, rgba.g, rgba.b), clamp(rgba.a, 0.0f, 1.0f));
    }
  }
  if (!any_value) return vec4(0.0f);
  st.samples = st.samples + 1u;
  return resoct_mix_result(weighted, combined);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_SLICE_GLSL_H
