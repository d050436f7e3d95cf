// resoct kernel: pre-integrated transfer functions (Engel et al. 2001, in the integral-function
// form without self-attenuation of Lum, Wylie and Ma 2004). See docs/rendering.md
// ("Pre-integration").
//
// Model. Per channel slot the transfer function becomes an extinction τ(v) = −ln(1 − α(v)) per
// reference step and an emission w(v) = c(v) τ(v), both piecewise LINEAR in the normalized value
// between the LUT entries (knots at v_i = i / (N − 1), N = RESOCT_TF_LUT_SIZE; τ_i from the LUT's
// α_i, capped at RESOCT_PREINT_TAU_MAX so that opaque entries stay finite). A ray segment of
// length L between samples with values s_f and s_b, over which the value is assumed to vary
// linearly, gets
//   α   = 1 − exp(−(L / Δ₀) · avg τ),   rgb = avg w / avg τ,   avg over [s_f, s_b]
// for any L (no 2D table). Values outside [0, 1] take the end knots' τ and w, as point lookups
// clamp; the average then weighs the parts outside [0, 1] by their length in value.
//
// Tables (host: resoct::preintegration_table, src/core/scene/preintegration.cpp), 2N vec4 per slot:
//   entry i        k_i = (w_i, τ_i)                       the knots
//   entry N + i    C_i = Σ_{m<i} (k_m + k_{m+1}) / 2       exact cumulative integral in bin units
// Integrals are evaluated as a tail in the first bin, whole bins C_j − C_{i+1} and a head in the
// last bin; within a bin the integrand is linear, so its average over a piece is its value at the
// piece's midpoint. The divisor is the sum of the same pieces' lengths, so the average is a convex
// combination of knot values: no cancellation as |s_b − s_f| → 0 (a segment inside one bin is
// exactly the model's point value at its mean). Cumulative differences only occur across whole
// bins (|s_b − s_f| ≥ 1/(N − 1)), where their float rounding is ~1e-7 of C.
//
// With s_f = s_b the segment is the model's point value; at the knots it equals the
// point-sampled, opacity-corrected lookup (tf.glsl.h + resoct_correct_opacity) up to float
// rounding, between knots it differs by the convexity of −ln(1 − α) within one LUT bin.
//
// Runs (ResoctPreintRay): a channel's consecutive values form a run, integrated segment by
// segment between sample midpoints, with half-step points at both ends so that a run covers
// exactly the steps it sampled. A run ends (and the next value starts a new one) when the channel
// has no value at a sample (a skipped node or brick, an empty node for that channel, a missing
// brick, NaN), at a slice/lens segment boundary and when the view LOD level changes (values of
// different levels are not one linear function). A coarser level substituted for a missing finer
// brick in residency mode is not detected: the point path mixes the levels in the same way.
//
// Accessor the including file must define BEFORE including this header:
//   vec4 resoct_read_preint(uint slot, uint index)   // index < 2 * RESOCT_TF_LUT_SIZE
#ifndef RESOCT_KERNEL_PREINTEGRATION_GLSL_H
#define RESOCT_KERNEL_PREINTEGRATION_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

/// Largest extinction per reference step (τ of an opaque LUT entry). A segment of 0.4 reference
/// steps through it has α = 1 − e^{−25.6}, which is 1 in float; a segment whose values are all
/// opaque is given α = 1 exactly, as the point path does.
RESOCT_CONST(float, RESOCT_PREINT_TAU_MAX, 64.0f);
/// Normalized values are clamped to [−this, 1 + this] first: ±inf and huge values stay finite in
/// bin units and their segments are dominated by the end knot, the limit of the average.
RESOCT_CONST(float, RESOCT_PREINT_VALUE_LIMIT, 64.0f);
/// Value spans below this many LUT bins use the point value at the mean (the averages agree to
/// this fraction of the integrand's slope per bin).
RESOCT_CONST(float, RESOCT_PREINT_MIN_SPAN, 1e-6f);

/// Knot k_i = (w_i, τ_i) of slot `slot`.
RESOCT_FN vec4 resoct_preint_knot(uint slot, uint i) {
  return resoct_read_preint(slot, i);
}

/// Cumulative integral C_i of the knots' linear interpolant from 0 to knot i (bin units).
RESOCT_FN vec4 resoct_preint_cumulative(uint slot, uint i) {
  return resoct_read_preint(slot, RESOCT_TF_LUT_SIZE + i);
}

/// The model's (w, τ) at x in bin units (x = v (N − 1)), clamped to the table.
RESOCT_FN vec4 resoct_preint_point(uint slot, float x) {
  float xc = clamp(x, 0.0f, float(RESOCT_TF_LUT_SIZE - 1u));
  uint i = min(uint(xc), RESOCT_TF_LUT_SIZE - 2u);
  return mix(resoct_preint_knot(slot, i), resoct_preint_knot(slot, i + 1u), xc - float(i));
}

/// ∫ (w, τ) over [xa, xb] (bin units, 0 <= xa <= xb <= N − 1), and in `len` the sum of the
/// pieces' lengths (xb − xa up to rounding) to divide by.
RESOCT_FN vec4 resoct_preint_inside(uint slot, float xa, float xb, RESOCT_OUT(float) len) {
  uint i = min(uint(xa), RESOCT_TF_LUT_SIZE - 2u);
  uint j = min(uint(xb), RESOCT_TF_LUT_SIZE - 2u);
  if (i == j) {
    len = xb - xa;
    return len * resoct_preint_point(slot, 0.5f * (xa + xb));
  }
  float fa = xa - float(i);
  float fb = xb - float(j);
  vec4 ki1 = resoct_preint_knot(slot, i + 1u);
  vec4 kj = resoct_preint_knot(slot, j);
  vec4 tail = (1.0f - fa) * mix(resoct_preint_knot(slot, i), ki1, 0.5f * (1.0f + fa));
  vec4 head = fb * mix(kj, resoct_preint_knot(slot, j + 1u), 0.5f * fb);
  vec4 whole = vec4(0.0f);
  if (j > i + 1u) {
    whole = resoct_preint_cumulative(slot, j) - resoct_preint_cumulative(slot, i + 1u);
  }
  len = (1.0f - fa) + float(j - i - 1u) + fb;
  return tail + whole + head;
}

/// Average (w, τ) of slot `slot` over the normalized values between `a` and `b` (any order, not
/// NaN).
RESOCT_FN vec4 resoct_preint_average(uint slot, float a, float b) {
  float scale = float(RESOCT_TF_LUT_SIZE - 1u);
  float xl = clamp(min(a, b), -RESOCT_PREINT_VALUE_LIMIT, 1.0f + RESOCT_PREINT_VALUE_LIMIT) * scale;
  float xh = clamp(max(a, b), -RESOCT_PREINT_VALUE_LIMIT, 1.0f + RESOCT_PREINT_VALUE_LIMIT) * scale;
  if (!(xh - xl > RESOCT_PREINT_MIN_SPAN)) return resoct_preint_point(slot, 0.5f * (xl + xh));
  // Outside the table the integrand is the end knot's: constant.
  float below = max(min(xh, 0.0f) - xl, 0.0f);
  float above = max(xh - max(xl, scale), 0.0f);
  vec4 sum = below * resoct_preint_knot(slot, 0u) +
             above * resoct_preint_knot(slot, RESOCT_TF_LUT_SIZE - 1u);
  float len = below + above;
  float il = clamp(xl, 0.0f, scale);
  float ih = clamp(xh, 0.0f, scale);
  if (ih > il) {
    float inside_len;
    sum = sum + resoct_preint_inside(slot, il, ih, inside_len);
    len = len + inside_len;
  }
  if (!(len > 0.0f)) return resoct_preint_point(slot, 0.5f * (xl + xh));
  return sum / len;
}

/// Straight colour and opacity of a segment of `step_ratio` = L / Δ₀ reference steps whose
/// values run from `sf` to `sb`. NaN at either end is transparent (as a NaN point lookup).
RESOCT_FN vec4 resoct_preint_segment(uint slot, float sf, float sb, float step_ratio) {
  if (isnan(sf) || isnan(sb) || !(step_ratio > 0.0f)) return vec4(0.0f);
  vec4 avg = resoct_preint_average(slot, sf, sb);
  float tau = avg.a;
  if (!(tau > 0.0f)) return vec4(0.0f);
  vec3 rgb = clamp(vec3(avg.r, avg.g, avg.b) / tau, vec3(0.0f), vec3(1.0f));
  float alpha = tau >= RESOCT_PREINT_TAU_MAX
                    ? 1.0f
                    : clamp(resoct_one_minus_exp(-step_ratio * tau), 0.0f, 1.0f);
  return vec4(rgb, alpha);
}

/// A tail's colour (8 bits per component) and slot (< 256) in one word.
RESOCT_FN uint resoct_preint_pack_tail(vec3 rgb, uint slot) {
  return (packUnorm4x8(vec4(rgb, 0.0f)) & 0x00FFFFFFu) | (slot << 24u);
}

/// Per-ray state. Samples sit at the midpoints m_i of the march's steps [t_i, t_i + Δ_i]; a
/// channel's run of consecutive values is integrated as
///   [t_first, m_first]        the first value as a point (half a step)
///   [m_{i−1}, m_i]            pre-integrated segments between consecutive values
///   [m_last, t_last + Δ_last] the last value as a point (the "tail", composited when the run
///                             ends: at the next sample without a value, at a view LOD change,
///                             at a slice/lens boundary or at the end of the ray)
/// so each run covers exactly the steps it sampled, like the point-sampled march, and nothing
/// is counted twice. `prev` holds the last values; `tail` the tails' straight colour (that of the
/// run's last segment, lit in effect specializations, so that shading treats a tail like the
/// sample it continues) at 8 bits per component and the channel's slot in the fourth byte (the
/// tail's extinction is that of the last value, looked up when the run ends). Keeping the state at
/// two words per slot matters on the GPU: the struct is passed in and out of the inlined helpers,
/// and a larger one made lavapipe's effect pipelines miss the frame timeout; `have` the open runs,
/// `got` the channels with a value at the current sample; `half` and `prev_half` are half the
/// current and previous step in reference steps.
struct ResoctPreintRay {
  float prev[RESOCT_MAX_SLOTS];
  uint tail[RESOCT_MAX_SLOTS];
  uint have;
  uint got;
  uint lod;
  float half_step;
  float prev_half_step;
};

RESOCT_FN void resoct_preint_ray_clear(RESOCT_OUT(ResoctPreintRay) pr) {
  for (uint i = 0u; i < RESOCT_MAX_SLOTS; ++i) {
    pr.prev[i] = 0.0f;
    pr.tail[i] = 0u;
  }
  pr.have = 0u;
  pr.got = 0u;
  pr.lod = 0xFFFFFFFFu;
  pr.half_step = 0.0f;
  pr.prev_half_step = 0.0f;
}

/// Channel c's value at the current sample: straight colour and opacity of the pre-integrated
/// segment from its previous value, or of the half-step point that starts a run. NaN is
/// transparent and ends the run.
RESOCT_FN vec4 resoct_preint_sample(RESOCT_INOUT(ResoctPreintRay) pr, uint c, uint slot,
                                    float value) {
  if (isnan(value)) return vec4(0.0f);
  bool cont = ((pr.have >> c) & 1u) != 0u;
  float sf = cont ? pr.prev[c] : value;
  float ratio = cont ? pr.prev_half_step + pr.half_step : pr.half_step;
  pr.prev[c] = value;
  pr.got = pr.got | (1u << c);
  vec4 seg = resoct_preint_segment(slot, sf, value, ratio);
  pr.tail[c] = resoct_preint_pack_tail(vec3(seg.r, seg.g, seg.b), slot);
  return seg;
}

/// Sets the colour the tail of channel c's run will have (effects: the lit colour).
RESOCT_FN void resoct_preint_set_tail_colour(RESOCT_INOUT(ResoctPreintRay) pr, uint c, vec3 rgb) {
  pr.tail[c] = resoct_preint_pack_tail(rgb, pr.tail[c] >> 24u);
}

/// Composites the tails of the runs in `ending` (intermixed like one sample) onto `acc`.
RESOCT_FN vec4 resoct_preint_composite_tails(RESOCT_INOUT(ResoctPreintRay) pr, uint ending,
                                             vec4 acc) {
  if (ending == 0u) return acc;
  vec4 weighted;
  float combined;
  resoct_mix_begin(weighted, combined);
  float ratio = pr.prev_half_step;
  // One pass per ending run, not per slot: lavapipe counts every loop back-edge against its
  // per-invocation guard (docs/vulkan-backend.md).
  for (uint e = ending; e != 0u; e = e & (e - 1u)) {
    uint c = uint(findLSB(e));
    vec4 t = unpackUnorm4x8(pr.tail[c]);
    float v = pr.prev[c];
    float tau = resoct_preint_average(pr.tail[c] >> 24u, v, v).a;
    float a =
        tau >= RESOCT_PREINT_TAU_MAX ? 1.0f : clamp(resoct_one_minus_exp(-ratio * tau), 0.0f, 1.0f);
    resoct_mix_add(weighted, combined, vec3(t.r, t.g, t.b), a);
  }
  return resoct_composite(acc, resoct_mix_result(weighted, combined));
}

/// Ends a sample, before its own mix is composited: the runs that did not continue here get
/// their tails composited onto `acc` (they lie before this sample's steps); the channels with a
/// value here carry on.
RESOCT_FN vec4 resoct_preint_end_sample(RESOCT_INOUT(ResoctPreintRay) pr, vec4 acc) {
  uint ending = pr.have & ~pr.got;
  vec4 out_acc = resoct_preint_composite_tails(pr, ending, acc);
  pr.have = pr.got;
  pr.got = 0u;
  pr.prev_half_step = pr.half_step;
  return out_acc;
}

/// The end of the ray or of a slice/lens segment: every open run's tail.
RESOCT_FN vec4 resoct_preint_flush(RESOCT_INOUT(ResoctPreintRay) pr, vec4 acc) {
  vec4 out_acc = resoct_preint_composite_tails(pr, pr.have, acc);
  pr.have = 0u;
  return out_acc;
}

/// Starts a sample at view LOD level `lod` whose step is `step_ratio` reference steps. A level
/// change ends every run (values of different levels are not one linear function): their tails
/// are composited onto `acc` here, before anything of this sample.
RESOCT_FN vec4 resoct_preint_begin_sample(RESOCT_INOUT(ResoctPreintRay) pr, uint lod,
                                          float step_ratio, vec4 acc) {
  vec4 out_acc = acc;
  if (lod != pr.lod && pr.have != 0u) out_acc = resoct_preint_flush(pr, acc);
  pr.lod = lod;
  pr.got = 0u;
  pr.half_step = 0.5f * step_ratio;
  return out_acc;
}

/// Straight colour and corrected opacity of a DVR channel's value at a sample of `step_ratio`
/// reference steps: pre-integrated with RESOCT_EFFECT_PREINT, else the point lookup.
RESOCT_FX_FN vec4 resoct_dvr_sample(RESOCT_INOUT(ResoctPreintRay) pr, uint c, uint slot,
                                    float value, float step_ratio) {
  RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
    return resoct_preint_sample(pr, c, slot, value);
  }
  vec4 rgba = resoct_tf_lookup(slot, value);
  return vec4(rgba.r, rgba.g, rgba.b, resoct_correct_opacity(rgba.a, step_ratio));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_PREINTEGRATION_GLSL_H
