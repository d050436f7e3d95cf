// resoct kernel: slice planes, rendered through the same page table, level choice and request
// machinery as the volume. See docs/rendering.md ("Slices and lens").
//
// A ray meets plane i at one parameter t (kept when it lies inside the volume interval). There
// the plane's pixel footprint picks the level: the view-depth footprint divided by |cos θ|
// between ray and plane normal (an oblique plane stretches a pixel over more voxels; the factor
// is capped at RESOCT_SLICE_MAX_STRETCH), against the same per-level size table as the volume.
// Each shown channel goes through the volume's residency-mode step (channel_sample.glsl.h): its
// target level when present, else a request (with the frame's strategy) and the nearest level
// partially resident in the finest octree node at the point, coarser first, then finer. An EMPTY
// brick is all zero, so on a slice it shows value 0. With window/level the channel is the opaque
// grey clamp((v - level) / window + 1/2, 0, 1), else the transfer function's colour and alpha as
// they are (a plane has no thickness to correct for). Channels are intermixed like volume samples
// (composite.glsl.h) and the result composited at t: what lies in front covers the slice, the slice
// covers what lies behind.
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
  RESOCT_PRECISE float denom = dot(n, dir_vox);
  if (abs(denom) < RESOCT_RAY_PARALLEL_EPS) return RESOCT_RAY_T_INF;
  RESOCT_PRECISE float th = dot(n, rel) / denom;
  return th;
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

/// One channel on a slice, through the volume path's own per-channel step
/// (resoct_residency_channel): the target level if present, else request it and substitute the
/// nearest level partially resident in the finest octree node at the point (coarser first, then
/// finer), each candidate checked by its page entry. False when nothing is present. EMPTY is
/// value 0 here (an EMPTY brick is all zero).
RESOCT_FN bool resoct_slice_channel(RESOCT_IN(ResoctSampleParams) p, RESOCT_IN(ResoctSlotInfo) s,
                                    uint node, uint target, ivec3 cell, vec3 frac,
                                    RESOCT_INOUT(uint) last_key, RESOCT_OUT(float) value,
                                    RESOCT_INOUT(ResoctRayStats) st) {
  uint res = resoct_residency_channel(p, s, node, target, cell, frac, last_key, value, st);
  if (res == RESOCT_CH_EMPTY) value = 0.0f;
  return res != RESOCT_CH_NONE;
}

/// Flat index of the finest octree node containing a cell inside the volume.
RESOCT_FN uint resoct_slice_node(RESOCT_FRAME_IN f, ivec3 cell) {
  uint depth = f.depth_count - 1u;
  RESOCT_IN(ResoctDepthInfo) D = resoct_read_depth(depth);
  uvec3 c = min(uvec3(cell) / uvec3(D.node_extent_x, D.node_extent_y, D.node_extent_z),
                uvec3(D.count_x - 1u, D.count_y - 1u, D.count_z - 1u));
  uvec3 c_log2 =
      uvec3(uint(findMSB(D.count_x)), uint(findMSB(D.count_y)), uint(findMSB(D.count_z)));
  uint local = 0u;
  for (uint d = 1u; d <= depth; ++d) {
    RESOCT_IN(ResoctDepthInfo) Dd = resoct_read_depth(d);
    uvec3 a = c >> (c_log2 - uvec3(uint(findMSB(Dd.count_x)), uint(findMSB(Dd.count_y)),
                                   uint(findMSB(Dd.count_z))));
    uint bits = 0u;
    uint shift = 0u;
    if (Dd.split_x != 0u) {
      bits = a.x & 1u;
      shift = 1u;
    }
    if (Dd.split_y != 0u) {
      bits = bits | ((a.y & 1u) << shift);
      shift = shift + 1u;
    }
    if (Dd.split_z != 0u) bits = bits | ((a.z & 1u) << shift);
    local = (local << Dd.child_shift) | bits;
  }
  return D.first_node + local;
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
  uint node = resoct_slice_node(f, cell);
  vec4 weighted;
  float combined;
  resoct_mix_begin(weighted, combined);
  bool any_value = false;
  uint mask = f.slice_channels[i];
  uint n = min(f.slot_count, RESOCT_MAX_SLOTS);
  for (uint c = 0u; c < n; ++c) {
    if (((mask >> c) & 1u) == 0u) continue;
    RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(c);
    uint last_key = RESOCT_REQUEST_KEY_NONE;
    float value;
    uint target = resoct_channel_level(lod, s.finest_level, s.coarsest_level);
    if (!resoct_slice_channel(p, s, node, target, cell, frac, last_key, value, st)) continue;
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
