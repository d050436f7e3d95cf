// resoct kernel: opacity correction, multi-channel intermixing and front-to-back compositing.
//
// Transfer-function alpha is the opacity of a reference step Δ₀ (one finest-level voxel, see
// docs/rendering.md). For a step Δ the opacity is α' = 1 − (1 − α)^(Δ/Δ₀), computed as
// 1 − e^y with y = (Δ/Δ₀) · ln(1 − α). Both halves lose precision in float: 1 − α rounds to 1
// for α below 6e-8, and 1 − e^y cancels for y near 0 (tiny steps). So ln(1 − α) and 1 − e^y use
// their Taylor series (to the 6th power) for α, |y| < 1/16, where the truncation error is below
// 1e-8 relative, and log2/exp2 elsewhere, where the cancellation error is below 2e-6 relative.
// α >= 1 stays 1; α <= 0, NaN α and Δ <= 0 give 0.
//
// Intermixing (accumulation level) of the channels at one sample, each with corrected alpha α'_c
// and straight colour c_c:
//   α   = 1 − Π_c (1 − α'_c)                 (accumulated as α ← α + (1 − α) α'_c, no cancellation)
//   rgb = α · Σ_c α'_c c_c / Σ_c α'_c         (premultiplied; 0 when Σ α'_c = 0)
// Both are symmetric in the channels, so the result does not depend on channel order (up to
// float rounding). For a single channel it is that channel. Since Π(1 − α'_c) = (Π(1 − α_c))^r,
// correcting then mixing equals mixing then correcting the opacity, and as Δ → 0 the colour
// weights α'_c tend to the extinction coefficients σ_c: the emission-absorption model of one
// medium with extinction Σσ_c and emission Σσ_c c_c.
//
// Front to back with premultiplied accumulator A and premultiplied sample s:
//   A ← A + (1 − A.a) s; terminate once A.a >= ert_opacity.
#ifndef RESOCT_KERNEL_COMPOSITE_GLSL_H
#define RESOCT_KERNEL_COMPOSITE_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_CONST(float, RESOCT_LN2, 0.69314718056f);
RESOCT_CONST(float, RESOCT_INV_LN2, 1.44269504089f);
/// Below this magnitude, ln(1 − α) and 1 − e^y use their series.
RESOCT_CONST(float, RESOCT_SERIES_LIMIT, 0.0625f);

/// ln(1 − a) for a in [0, 1), accurate also for tiny a.
RESOCT_FN float resoct_log_one_minus(float a) {
  if (a < RESOCT_SERIES_LIMIT) {
    // −(a + a²/2 + a³/3 + a⁴/4 + a⁵/5 + a⁶/6)
    return -a *
           (1.0f + a * (0.5f + a * (0.33333333f + a * (0.25f + a * (0.2f + a * 0.16666667f)))));
  }
  return log2(1.0f - a) * RESOCT_LN2;
}

/// 1 − e^y for y <= 0, accurate also for y near 0.
RESOCT_FN float resoct_one_minus_exp(float y) {
  if (y > -RESOCT_SERIES_LIMIT) {
    // −(y + y²/2 + y³/6 + y⁴/24 + y⁵/120 + y⁶/720)
    return -y *
           (1.0f + y * (0.5f + y * (0.16666667f +
                                    y * (0.041666668f + y * (0.0083333333f + y * 0.0013888889f)))));
  }
  return 1.0f - exp2(y * RESOCT_INV_LN2);
}

/// Opacity of a step of `step_ratio` = Δ/Δ₀ reference steps for reference opacity `alpha`.
RESOCT_FN float resoct_correct_opacity(float alpha, float step_ratio) {
  if (!(alpha > 0.0f) || !(step_ratio > 0.0f)) return 0.0f;
  if (alpha >= 1.0f) return 1.0f;
  return clamp(resoct_one_minus_exp(step_ratio * resoct_log_one_minus(alpha)), 0.0f, 1.0f);
}

/// Premultiplied sample from a straight colour and an (already corrected) opacity.
RESOCT_FN vec4 resoct_premultiply(vec3 rgb, float alpha) {
  return vec4(rgb * alpha, alpha);
}

/// Straight colour from a premultiplied one (0 where alpha is 0).
RESOCT_FN vec4 resoct_unpremultiply(vec4 c) {
  if (!(c.a > 0.0f)) return vec4(0.0f);
  return vec4(vec3(c.r, c.g, c.b) / c.a, c.a);
}

/// Starts intermixing one sample: weighted colour sum (rgb = Σ α'_c c_c, a = Σ α'_c) and the
/// combined alpha are zero.
RESOCT_FN void resoct_mix_begin(RESOCT_OUT(vec4) weighted, RESOCT_OUT(float) combined_alpha) {
  weighted = vec4(0.0f);
  combined_alpha = 0.0f;
}

/// Adds one channel: straight colour `rgb` with corrected opacity `alpha`.
RESOCT_FN void resoct_mix_add(RESOCT_INOUT(vec4) weighted, RESOCT_INOUT(float) combined_alpha,
                              vec3 rgb, float alpha) {
  weighted = weighted + vec4(rgb * alpha, alpha);
  combined_alpha = combined_alpha + (1.0f - combined_alpha) * alpha;
}

/// Adds one channel given premultiplied: (rgb · α', α'), as from a step level's LUT
/// (kernel/step_lut.glsl.h). The same sums as resoct_mix_add with the product precomputed.
RESOCT_FN void resoct_mix_add_premultiplied(RESOCT_INOUT(vec4) weighted,
                                            RESOCT_INOUT(float) combined_alpha,
                                            vec4 premultiplied) {
  weighted = weighted + premultiplied;
  combined_alpha = combined_alpha + (1.0f - combined_alpha) * premultiplied.a;
}

/// The mixed sample, premultiplied.
RESOCT_FN vec4 resoct_mix_result(vec4 weighted, float combined_alpha) {
  if (!(weighted.a > 0.0f)) return vec4(0.0f);
  vec3 rgb = vec3(weighted.r, weighted.g, weighted.b) * (combined_alpha / weighted.a);
  return vec4(rgb, combined_alpha);
}

/// Front-to-back "under" operator on premultiplied colours.
RESOCT_FN vec4 resoct_composite(vec4 accumulated, vec4 sample_premultiplied) {
  return accumulated + (1.0f - accumulated.a) * sample_premultiplied;
}

/// Early ray termination test.
RESOCT_FN bool resoct_saturated(vec4 accumulated, float ert_opacity) {
  return accumulated.a >= ert_opacity;
}

/// The accumulated ray over a straight-alpha background colour; premultiplied result.
RESOCT_FN vec4 resoct_over_background(vec4 accumulated, vec4 background) {
  return resoct_composite(
      accumulated,
      resoct_premultiply(vec3(background.r, background.g, background.b), background.a));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_COMPOSITE_GLSL_H
