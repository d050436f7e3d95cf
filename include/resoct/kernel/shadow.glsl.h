// resoct kernel: shadow rays through a coarser level of detail (paper 004 §7.2).
//
// A shaded sample or an isosurface hit casts one ray toward the light. It marches the level
// lod + shadow_lod_shift (per channel clamped to its [finest, coarsest]), where lod is the view
// LOD level at the sample, with a step of one voxel of that level (times step_scale; Eq.
// 8.2-8.3 along the light direction), so shift 1 is paper 004's "shadow dP/dV twice the viewing
// dP/dV". It starts one shadow step away from the sample (no self-shadowing) and ends at the
// volume exit or at a point light. It uses the residency octree exactly like a primary ray:
// nodes empty for every absorbing channel are skipped on the same sample grid, missing bricks
// are requested (same request machinery and strategy) and substituted. DVR channels absorb with
// their corrected opacity; an isosurface channel blocks the light completely where the value
// crosses one of its isovalues between two shadow samples; MIP/AIP channels do not absorb. The
// result is the transmittance in [0, 1]; the march stops once it falls below 1 − ert_opacity.
//
// Accessors: as listed in traverse.glsl.h.
#ifndef RESOCT_KERNEL_SHADOW_GLSL_H
#define RESOCT_KERNEL_SHADOW_GLSL_H

#include "resoct/kernel/camera_ray.glsl.h"
#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/gradient.glsl.h"
#include "resoct/kernel/node_class.glsl.h"
#include "resoct/kernel/projection.glsl.h"
#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

/// Whether the value crossed any isovalue of an iso slot between `prev` and `v`.
RESOCT_FN bool resoct_iso_crossed(RESOCT_IN(ResoctSlotInfo) s, float prev, float v,
                                  RESOCT_OUT(float) iso) {
  iso = 0.0f;
  for (uint k = 0u; k < s.iso_count && k < RESOCT_MAX_ISOVALUES; ++k) {
    float x = k == 0u ? s.iso0 : (k == 1u ? s.iso1 : (k == 2u ? s.iso2 : s.iso3));
    if ((prev < x) != (v < x)) {
      iso = x;
      return true;
    }
  }
  return false;
}

/// Transmittance toward the light from the level-0 position (cell, frac). `light` is the unit
/// box-space vector toward the light, `max_t` the distance to a point light (box units; huge for
/// directional light), `lod` the view LOD level at the position, `live` the slots that take
/// part (see traverse.glsl.h).
RESOCT_FN float resoct_shadow_transmittance(RESOCT_IN(ResoctSampleParams) sp,
                                            RESOCT_IN(ResoctFxParams) p, uint n, uint live,
                                            ivec3 cell0, vec3 frac0, vec3 light, float max_t,
                                            uint lod, RESOCT_INOUT(ResoctRayStats) st) {
  st.shadow_rays = st.shadow_rays + 1u;
  vec3 vpb = resoct_fx_voxels_per_box(p);
  vec3 dir_vox = light * vpb;
  vec3 inv_vox = resoct_ray_inverse(dir_vox);
  uint base = min(lod + p.shadow_lod_shift, sp.level_count - 1u);
  RESOCT_IN(ResoctLevelInfo) Lb = resoct_read_level(base);
  vec3 level_voxel = vec3(uvec3(1u) << resoct_level_factor(Lb)) / vpb;
  float dt = resoct_step_size(light, level_voxel, p.step_scale, p.min_step);
  float inv_dt = 1.0f / dt;
  vec3 vol_lo = vec3(-cell0);
  vec3 vol_hi = vec3(ivec3(int(p.extent_x), int(p.extent_y), int(p.extent_z)) - cell0);
  float t_exit = min(resoct_ray_box_inv(frac0, inv_vox, vol_lo, vol_hi).y, max_t);
  uint depth = resoct_traversal_depth_for(p.start_depth, p.depth_count, dt);
  RESOCT_IN(ResoctDepthInfo) Dt = resoct_read_depth(depth);
  uvec3 dlog2 = resoct_depth_count_log2(Dt);

  float transmit = 1.0f;
  float prev[RESOCT_MAX_SLOTS];
  uint have_prev = 0u;  // iso slots with a previous shadow sample
  uint last_key = RESOCT_REQUEST_KEY_NONE;
  uint cached_node = RESOCT_NONE_U;
  uint empty = 0u;
  uint homog = 0u;
  uint all = n >= 32u ? 0xFFFFFFFFu : ((1u << n) - 1u);
  float t = dt;
  for (uint it = 0u; it < p.max_iterations && t_exit - t > RESOCT_SEGMENT_EPS * dt; ++it) {
    float seg = resoct_segment_length(t, dt, t_exit);
    float tm = t + 0.5f * seg;
    ivec3 cell;
    vec3 frac;
    resoct_ray_position(cell0, frac0, dir_vox, tm, cell, frac);
    resoct_fx_clamp(p, cell, frac);
    uvec3 coord = resoct_node_coord(Dt, cell);
    uint node = resoct_node_index(depth, coord, dlog2);
    if (node != cached_node) {
      cached_node = node;
      empty = 0u;
      homog = 0u;
      for (uint c = 0u; c < n; ++c) {
        RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(c);
        uint cls = RESOCT_NODE_CLASS_EMPTY;
        if (((live >> c) & 1u) != 0u && !resoct_is_projection(s)) {
          cls = resoct_node_class_carried(node, depth, p.start_depth, s, sp.node_slot_count);
          // A homogeneous ancestor's value is only known at the ancestor: read bricks.
          if (cls == RESOCT_NODE_CLASS_HOMOGENEOUS &&
              resoct_node_class(node, s, sp.node_slot_count) != RESOCT_NODE_CLASS_HOMOGENEOUS) {
            cls = RESOCT_NODE_CLASS_VISIBLE;
          }
        }
        if (cls == RESOCT_NODE_CLASS_EMPTY) empty = empty | (1u << c);
        if (cls == RESOCT_NODE_CLASS_HOMOGENEOUS) homog = homog | (1u << c);
      }
    }
    if (empty == all) {
      uvec3 ne = uvec3(Dt.node_extent_x, Dt.node_extent_y, Dt.node_extent_z);
      float e = resoct_box_exit(cell, frac, inv_vox, ivec3(coord * ne), vec3(ne));
      float k = max(1.0f, resoct_ceil((0.5f * seg + e - 0.5f * dt) * inv_dt));
      t = resoct_advance_t(t, k * dt);
      continue;
    }
    for (uint c = 0u; c < n; ++c) {
      if (((empty >> c) & 1u) != 0u) continue;
      RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(c);
      float value = 0.0f;
      uint res = RESOCT_CH_VALUE;
      if (((homog >> c) & 1u) != 0u) {
        uint mm = resoct_read_node(resoct_node_base(node, s.slot, sp.node_slot_count) +
                                   RESOCT_NODE_MINMAX);
        value = float(resoct_node_min16(mm)) / 65535.0f;
      } else {
        uint target = resoct_channel_level(base, s.finest_level, s.coarsest_level);
        res = resoct_residency_channel(sp, s, node, target, cell, frac, last_key, value, st);
      }
      if (res != RESOCT_CH_VALUE) continue;
      if (s.mode == RESOCT_CHANNEL_ISO) {
        float iso;
        if (((have_prev >> c) & 1u) != 0u && resoct_iso_crossed(s, prev[c], value, iso)) {
          return 0.0f;
        }
        prev[c] = value;
        have_prev = have_prev | (1u << c);
      } else {
        float a = resoct_correct_opacity(resoct_tf_lookup(s.slot, value).a,
                                         resoct_step_ratio(seg, p.ref_step));
        transmit = transmit * (1.0f - a);
      }
    }
    if (transmit <= 1.0f - p.ert_opacity) return transmit;
    t = resoct_advance_t(t, seg);
  }
  return transmit;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_SHADOW_GLSL_H
