// resoct kernel: the samples of one ray segment with a single source, without effects.
//
// Between two decisions of the march (traverse.glsl.h, docs/rendering.md "Segments") every
// channel's source is fixed. When one channel yields values there and no effect is on (the
// plain kernel), a sample is only: the source's value at the padded-brick position affine in t,
// the transfer function, the opacity correction and the "under" operator. This loop does exactly
// that, with the same arithmetic as the general per-sample path (a single channel's intermixed
// sample, weighted / combined, equals its premultiplied colour bit for bit), so images and
// statistics do not depend on which path ran.
//
// In C++ the loop is a function of its own (RESOCT_LOOP_FN): the march around it holds the
// decision state of all channels, and compiled into the march the loop's position, accumulator
// and statistics lived in stack slots. GLSL compilers inline it.
#ifndef RESOCT_KERNEL_SEGMENT_SAMPLES_GLSL_H
#define RESOCT_KERNEL_SEGMENT_SAMPLES_GLSL_H

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/step_lut.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

/// Samples `src` (RESOCT_CH_VALUE) from the sample at `tm` (segment [t, t + seg)) while its
/// midpoint lies before `seg_next`. Full steps (seg == dt) of a ray with a step level
/// (`step_level`, kernel/step_lut.glsl.h) take their premultiplied, corrected colour from that
/// level's LUT; shorter ones, and every step without a level, correct per sample. t is step
/// `grid_j` of the grid that starts at `t_grid` (resoct_grid_t); grid_j follows t. Returns true
/// when the ray saturated (early termination); otherwise `t` is the start of the next sample, which
/// the march must see first: the ray's end, the iteration cap, or a new decision. `acc` is the
/// premultiplied accumulated colour; samples, brick accesses, iterations and marched length are
/// counted in `stats` as the march's per-sample path counts them.
RESOCT_LOOP_FN bool resoct_segment_samples(RESOCT_FRAME_IN f, RESOCT_IN(ResoctSource) src, float dt,
                                           uint step_level, float t_exit, float seg_next, float seg,
                                           float tm, float t_grid, RESOCT_INOUT(uint) grid_j,
                                           RESOCT_INOUT(float) t, RESOCT_INOUT(vec4) acc,
                                           RESOCT_INOUT(ResoctRayStats) stats) {
  // The loop's state in locals, written back once: in C++ the references could alias nothing
  // here, but locals make it plain to the compiler (and cost nothing in GLSL).
  float t_now = t;
  uint j = grid_j;
  vec4 a = acc;
  uint samples = stats.samples;
  uint accesses = stats.brick_accesses;
  uint iterations = stats.iterations;
  float marched = stats.marched;
  bool mapped = src.cache_slot != RESOCT_SOURCE_NO_SLOT;
  bool saturated = false;
  for (;;) {
    float value = src.value;
    if (mapped) {
      accesses = accesses + 1u;
      value = resoct_normalize_value(
          resoct_sample_cache(src.cache_slot, src.ray_base + tm * src.ray_dir), src.range_lo,
          src.inv_range_width);
    }
    samples = samples + 1u;
    // resoct_mix_result of this one channel: its colour premultiplied (0 where alpha is 0).
    vec4 sample_pm;
    if (seg == dt && step_level != RESOCT_STEP_LEVEL_NONE) {
      vec4 p = resoct_step_lut_lookup(src.tf_slot, step_level, f.step_level_count, value);
      sample_pm = p.a > 0.0f ? p : vec4(0.0f);
    } else {
      vec4 rgba = resoct_tf_lookup(src.tf_slot, value);
      float alpha = resoct_correct_opacity(rgba.a, resoct_step_ratio(seg, f.ref_step));
      sample_pm =
          alpha > 0.0f ? resoct_premultiply(vec3(rgba.r, rgba.g, rgba.b), alpha) : vec4(0.0f);
    }
    a = resoct_composite(a, sample_pm);
    if (resoct_saturated(a, f.ert_opacity)) {
      saturated = true;
      break;
    }
    marched = marched + seg;
    j = j + 1u;
    t_now = resoct_grid_t(t_grid, j, dt, t_now);
    if (!(t_exit - t_now > RESOCT_SEGMENT_EPS * dt) || iterations >= f.max_iterations) break;
    seg = resoct_segment_length(t_now, dt, t_exit);
    tm = t_now + 0.5f * seg;
    if (!(tm < seg_next)) break;
    iterations = iterations + 1u;
  }
  t = t_now;
  grid_j = j;
  acc = a;
  stats.samples = samples;
  stats.brick_accesses = accesses;
  stats.iterations = iterations;
  stats.marched = marched;
  return saturated;
}

#ifdef __cplusplus
/// The samples of one segment in which several channels yield values (the bits of `values`
/// among the first n entries of `src`, each RESOCT_CH_VALUE), without effects: per sample the
/// march's own per-sample pass (traverse.glsl.h), i.e. every such channel sampled and mixed in
/// channel order (a full step of a ray with a step level from the level's LUT, any other step
/// corrected per sample), then one composite; the contract is resoct_segment_samples'. C++ only:
/// the CPU backend replaces it with packets (RESOCT_SEGMENT_SAMPLES_MULTI,
/// src/backend_cpu/segment_packets_multi.hpp) and tests those against it; GLSL runs the march's
/// pass, whose arithmetic this repeats operation for operation.
RESOCT_LOOP_FN bool resoct_segment_samples_multi(RESOCT_FRAME_IN f, const ResoctSource* src,
                                                 uint values, uint n, float dt, uint step_level,
                                                 float t_exit, float seg_next, float seg, float tm,
                                                 float t_grid, RESOCT_INOUT(uint) grid_j,
                                                 RESOCT_INOUT(float) t, RESOCT_INOUT(vec4) acc,
                                                 RESOCT_INOUT(ResoctRayStats) stats) {
  float t_now = t;
  uint j = grid_j;
  vec4 a = acc;
  ResoctRayStats st = stats;
  bool saturated = false;
  for (;;) {
    vec4 weighted;
    float combined;
    resoct_mix_begin(weighted, combined);
    bool from_level = seg == dt && step_level != RESOCT_STEP_LEVEL_NONE;
    for (uint c = 0u; c < n; ++c) {
      if (((values >> c) & 1u) == 0u) continue;
      float value;
      resoct_source_sample_t(src[c], tm, value, st);
      if (from_level) {
        resoct_mix_add_premultiplied(
            weighted, combined,
            resoct_step_lut_lookup(src[c].tf_slot, step_level, f.step_level_count, value));
      } else {
        vec4 rgba = resoct_tf_lookup(src[c].tf_slot, value);
        resoct_mix_add(weighted, combined, vec3(rgba.r, rgba.g, rgba.b),
                       resoct_correct_opacity(rgba.a, resoct_step_ratio(seg, f.ref_step)));
      }
    }
    st.samples = st.samples + 1u;
    a = resoct_composite(a, resoct_mix_result(weighted, combined));
    if (resoct_saturated(a, f.ert_opacity)) {
      saturated = true;
      break;
    }
    st.marched = st.marched + seg;
    j = j + 1u;
    t_now = resoct_grid_t(t_grid, j, dt, t_now);
    if (!(t_exit - t_now > RESOCT_SEGMENT_EPS * dt) || st.iterations >= f.max_iterations) break;
    seg = resoct_segment_length(t_now, dt, t_exit);
    tm = t_now + 0.5f * seg;
    if (!(tm < seg_next)) break;
    st.iterations = st.iterations + 1u;
  }
  t = t_now;
  grid_j = j;
  acc = a;
  stats = st;
  return saturated;
}
#endif

RESOCT_KERNEL_END

// The loop the march calls. A backend may replace it with an implementation of the same contract
// and the same arithmetic per sample by defining RESOCT_SEGMENT_SAMPLES before including
// traverse.glsl.h: the CPU backend runs packets of four samples
// (src/backend_cpu/segment_packets.hpp).
#ifndef RESOCT_SEGMENT_SAMPLES
#define RESOCT_SEGMENT_SAMPLES resoct_segment_samples
#endif

#endif  // RESOCT_KERNEL_SEGMENT_SAMPLES_GLSL_H
