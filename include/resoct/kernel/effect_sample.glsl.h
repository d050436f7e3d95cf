// resoct kernel: what the declared effects do with one channel's value at one sample
// (docs/rendering.md "Effects"). Called by traverse.glsl.h only from specializations whose
// RESOCT_EFFECTS is not 0; the plain kernel never reaches this code.
//
//   dvr   TF colour and corrected opacity (pre-integrated over the segment from the channel's
//         previous value with RESOCT_EFFECT_PREINT); with "shading" the colour is Blinn-Phong lit
//         with the gradient normal, with "shadows" the diffuse and specular terms are scaled by the
//         transmittance of a shadow ray (samples above RESOCT_SHADOW_MIN_ALPHA only).
//   iso   a crossing of an isovalue between the channel's previous and current sample is refined
//         on the trilinear cells (isosurface.glsl.h); the surface is composited at the hit,
//         before the current sample, with the TF colour and alpha at the isovalue, always
//         shaded with its gradient normal (and shadowed with "shadows").
//   mip   running maximum of the value clamped to [0, 1];
//   aip   integral of the clamped value over the ray's length in the volume.
// MIP/AIP results go through their TF after the march, are intermixed like one sample, and are
// composited behind everything the ray accumulated (resoct_fx_projection_composite).
//
// Accessors: as listed in traverse.glsl.h.
#ifndef RESOCT_KERNEL_EFFECT_SAMPLE_GLSL_H
#define RESOCT_KERNEL_EFFECT_SAMPLE_GLSL_H

#include "resoct/kernel/camera_ray.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/gradient.glsl.h"
#include "resoct/kernel/isosurface.glsl.h"
#include "resoct/kernel/preintegration.glsl.h"
#include "resoct/kernel/projection.glsl.h"
#include "resoct/kernel/shadow.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

/// Per-ray state of the effects.
struct ResoctFxRay {
  float prev_v[RESOCT_MAX_SLOTS];  // iso: the channel's previous value
  float prev_t[RESOCT_MAX_SLOTS];  // iso: its sample parameter
  uint have_prev;                  // iso: slots with a previous value
  float proj[RESOCT_MAX_SLOTS];    // mip: running maximum; aip: integral of the value
};

/// Per-ray constants of the effect code.
struct ResoctFxRayConst {
  ivec3 o_cell;  // ray origin, exact cell + fraction (level-0 voxels)
  vec3 o_frac;
  vec3 dir_box;  // unit direction, box space
  vec3 dir_vox;  // direction in level-0 voxels per box unit
  uint n;        // slot count
  uint live;     // slots whose TF is visible somewhere
};

RESOCT_FN void resoct_fx_ray_clear(RESOCT_OUT(ResoctFxRay) fx) {
  fx.have_prev = 0u;
  for (uint i = 0u; i < RESOCT_MAX_SLOTS; ++i) {
    fx.prev_v[i] = 0.0f;
    fx.prev_t[i] = 0.0f;
    fx.proj[i] = 0.0f;
  }
}

RESOCT_FN float resoct_isovalue(RESOCT_IN(ResoctSlotInfo) s, uint k) {
  return k == 0u ? s.iso0 : (k == 1u ? s.iso1 : (k == 2u ? s.iso2 : s.iso3));
}

/// Lit colour of a surface or sample of slot `s` at `level` and the position (cell, frac). When
/// the position is the march's sample at t whose value came from `src` at the same level
/// (`at_sample`), the gradient taps read the source's brick directly.
RESOCT_FX_FN vec3 resoct_fx_shade(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                                  ResoctFxRayConst rc, RESOCT_IN(ResoctSlotInfo) s, uint level,
                                  uint lod, ivec3 cell, vec3 frac, float value, vec3 rgb,
                                  bool cast_shadow, bool at_sample, RESOCT_IN(ResoctSource) src,
                                  float t, RESOCT_INOUT(ResoctRayStats) st) {
  vec3 g;
  if (!(at_sample && src.level == level && resoct_source_gradient(sp, p, src, t, cell, value, g))) {
    g = resoct_gradient(sp, p, s, level, cell, frac, value);
  }
  st.gradient_evals = st.gradient_evals + 1u;
  vec3 pos_box = (vec3(cell) + frac) / resoct_fx_voxels_per_box(p);
  vec3 light = resoct_light_vector(p, pos_box, rc.dir_box);
  float shadow = 1.0f;
  RESOCT_IF_FX(RESOCT_EFFECT_SHADOWS) {
    if (cast_shadow) {
      float max_t = RESOCT_RAY_T_INF;
      if (p.light_kind == RESOCT_LIGHT_POINT) {
        max_t = length(vec3(p.light_x, p.light_y, p.light_z) - pos_box);
      }
      shadow = resoct_shadow_transmittance(sp, p, rc.n, rc.live, cell, frac, light, max_t, lod, st);
    }
  }
  return resoct_blinn_phong(p, rgb, g, light, rc.dir_box, shadow);
}

/// Iso channel at a sample: brackets a crossing against the channel's previous sample and
/// refines it. When the two samples straddle several isovalues, the one nearest the previous
/// value (crossed first by a monotone field) is refined, the others are not drawn in this step.
/// True with the hit's parameter and isovalue; the current sample becomes the previous one
/// either way. One refinement per call keeps the inlined GPU code small.
RESOCT_FN bool resoct_fx_iso_hit(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                                 ResoctFxRayConst rc, uint c, RESOCT_IN(ResoctSlotInfo) s,
                                 float value, uint level, float tm, RESOCT_INOUT(ResoctFxRay) fx,
                                 RESOCT_OUT(float) t_hit, RESOCT_OUT(float) iso_hit) {
  t_hit = tm;
  iso_hit = 0.0f;
  bool found = false;
  float pv = fx.prev_v[c];
  float pt = fx.prev_t[c];
  if (((fx.have_prev >> c) & 1u) != 0u) {
    for (uint k = 0u; k < s.iso_count && k < RESOCT_MAX_ISOVALUES; ++k) {
      float x = resoct_isovalue(s, k);
      if ((pv < x) == (value < x)) continue;
      if (!found || abs(x - pv) < abs(iso_hit - pv)) iso_hit = x;
      found = true;
    }
  }
  fx.prev_v[c] = value;
  fx.prev_t[c] = tm;
  fx.have_prev = fx.have_prev | (1u << c);
  if (!found) return false;
  // Refined on the level of the current sample; when the samples come from different levels
  // (an LOD transition or a substitution) or a brick is missing, the trilinear cells may hold
  // no root: interpolate linearly then, so that the surface has no hole.
  if (!resoct_iso_refine(sp, p, s, level, iso_hit, rc.o_cell, rc.o_frac, rc.dir_vox, pt, tm,
                         t_hit)) {
    t_hit = pt + (tm - pt) * clamp((iso_hit - pv) / (value - pv), 0.0f, 1.0f);
  }
  return true;
}

/// One channel's value at a sample under the declared effects (see the file comment). `level`
/// is the level the value came from, `src` the segment's source of the channel, `lod` the view
/// LOD level, `seg` the segment length. The lighting code appears once (one call of
/// resoct_fx_shade) so that GPU compilers, which inline everything, compile it once.
RESOCT_FX_FN void resoct_fx_channel(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                                    ResoctFxRayConst rc, uint c, RESOCT_IN(ResoctSlotInfo) s,
                                    RESOCT_IN(ResoctSource) src, float value, uint level, uint lod,
                                    float seg, float tm, ivec3 cell, vec3 frac,
                                    RESOCT_INOUT(ResoctFxRay) fx, RESOCT_INOUT(ResoctPreintRay) pr,
                                    RESOCT_INOUT(vec4) weighted, RESOCT_INOUT(float) combined,
                                    RESOCT_INOUT(vec4) acc, RESOCT_INOUT(ResoctRayStats) st) {
  RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
    if (s.mode == RESOCT_CHANNEL_MIP) {
      fx.proj[c] = max(fx.proj[c], clamp(value, 0.0f, 1.0f));
      return;
    }
    if (s.mode == RESOCT_CHANNEL_AIP) {
      fx.proj[c] = fx.proj[c] + clamp(value, 0.0f, 1.0f) * seg;
      return;
    }
  }
  bool surface = false;
  ivec3 pc = cell;
  vec3 pf = frac;
  uint pl = level;
  float pv = value;
  RESOCT_IF_FX(RESOCT_EFFECT_ISO) {
    if (s.mode == RESOCT_CHANNEL_ISO) {
      float th;
      if (!resoct_fx_iso_hit(sp, p, rc, c, s, value, level, tm, fx, th, pv)) return;
      resoct_ray_position(rc.o_cell, rc.o_frac, rc.dir_vox, th, pc, pf);
      resoct_fx_clamp(p, pc, pf);
      surface = true;
    }
  }
  // A surface keeps its TF alpha; a DVR sample's alpha is corrected for the segment (or comes
  // from the pre-integrated segment, whose colour shading then multiplies like a point's).
  vec4 rgba;
  float a;
  if (surface) {
    rgba = resoct_tf_lookup(s.slot, pv);
    a = min(rgba.a, 1.0f);
  } else {
    rgba = RESOCT_FX(resoct_dvr_sample)(pr, c, s.slot, pv, resoct_step_ratio(seg, p.ref_step));
    a = rgba.a;
  }
  vec3 rgb = vec3(rgba.r, rgba.g, rgba.b);
  bool lit = surface;
  RESOCT_IF_FX(RESOCT_EFFECT_SHADING) {
    lit = true;
  }
  if (lit && a > 0.0f) {
    rgb = RESOCT_FX(resoct_fx_shade)(sp, p, rc, s, pl, lod, pc, pf, pv, rgb,
                                     surface || a > RESOCT_SHADOW_MIN_ALPHA, !surface, src, tm, st);
  }
  RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
    if (!surface) resoct_preint_set_tail_colour(pr, c, rgb);
  }
  if (surface) {
    acc = resoct_composite(acc, resoct_premultiply(rgb, a));
  } else {
    resoct_mix_add(weighted, combined, rgb, a);
  }
}

/// MIP/AIP results behind the accumulated colour. `length` is the ray's length in the volume.
RESOCT_FN vec4 resoct_fx_projection_composite(ResoctFxRay fx, uint n, uint live, float length,
                                              vec4 acc) {
  vec4 weighted;
  float combined;
  resoct_mix_begin(weighted, combined);
  for (uint c = 0u; c < n; ++c) {
    RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(c);
    if (((live >> c) & 1u) == 0u || !resoct_is_projection(s)) continue;
    float v = fx.proj[c];
    if (s.mode == RESOCT_CHANNEL_AIP) v = length > 0.0f ? v / length : 0.0f;
    vec4 rgba = resoct_tf_lookup(s.slot, v);
    resoct_mix_add(weighted, combined, vec3(rgba.r, rgba.g, rgba.b), clamp(rgba.a, 0.0f, 1.0f));
  }
  return resoct_composite(acc, resoct_mix_result(weighted, combined));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_EFFECT_SAMPLE_GLSL_H
