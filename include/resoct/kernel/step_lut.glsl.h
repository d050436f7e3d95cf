// resoct kernel: step levels and the opacity-corrected, premultiplied transfer-function LUTs of
// each level (docs/rendering.md "Step levels").
//
// A ray's full step is constant (Eq. 8.2-8.3, kernel/step.glsl.h), so the opacity correction
// 1 − (1 − α)^(Δ/Δ₀) of its full steps depends on the LUT entry alone. The ratio Δ/Δ₀ varies
// continuously with the ray's direction, though, so the kernel rounds it DOWN to a *step level*:
// the float whose bits are the ratio's bits with all but the top `23 − step_level_shift`
// mantissa bits cleared (2^(23 − shift) levels per octave, linearly spaced inside it). Rounding
// down keeps the step at most the Eq. 8.3 step (the march samples at most 1/2^(23 − shift)
// more densely), and bit operations give the same level on every backend, where a log2 would
// not. For every level of the frame's range the host builds, per channel slot, a LUT whose entry
// i is the straight-alpha TF entry i with its alpha corrected for that level's ratio and its
// colour premultiplied by the corrected alpha (computed in double). A full step's sample is then
// the linear interpolation of two such entries: no logarithm, no exponential, no premultiply.
// Shorter steps (the last one of a ray or slice segment) correct per sample as before
// (kernel/composite.glsl.h).
//
// Interpolating corrected, premultiplied entries (opacity-weighted colour interpolation) differs
// from correcting the interpolated entry by second-order terms within one LUT cell: the two
// agree exactly at the entries and for constant transfer functions.
//
// Frame fields (ResoctFrame): step_level_shift (mantissa bits dropped), step_level_first (the
// first level's ratio bits >> shift), step_level_count (levels in the tables; 0: no tables, every
// sample corrects per sample). The LUT of slot s and level l starts at entry
// (s * step_level_count + l) * RESOCT_TF_LUT_SIZE.
//
// Accessor the including file must define BEFORE including this header:
//   vec4 resoct_read_step_lut(uint index)   premultiplied, corrected entry
#ifndef RESOCT_KERNEL_STEP_LUT_GLSL_H
#define RESOCT_KERNEL_STEP_LUT_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

/// No step level: the ray's samples correct their opacity per sample.
RESOCT_CONST(uint, RESOCT_STEP_LEVEL_NONE, 0xFFFFFFFFu);

/// The level (index into the frame's tables) of a full step of `ratio` reference steps, or
/// RESOCT_STEP_LEVEL_NONE when the frame has no table for it.
RESOCT_FN uint resoct_step_level(RESOCT_FRAME_IN f, float ratio) {
  if (!(ratio > 0.0f)) return RESOCT_STEP_LEVEL_NONE;
  uint k = floatBitsToUint(ratio) >> f.step_level_shift;
  uint level = k - f.step_level_first;  // wraps for k below the first level
  return level < f.step_level_count ? level : RESOCT_STEP_LEVEL_NONE;
}

/// The ratio Δ/Δ₀ of step level `level`: the ray's ratio rounded down to the level.
RESOCT_FN float resoct_step_level_ratio(RESOCT_FRAME_IN f, uint level) {
  return uintBitsToFloat((f.step_level_first + level) << f.step_level_shift);
}

/// Premultiplied, opacity-corrected sample of normalized value v for a full step of `level` in
/// slot `slot`: resoct_tf_lookup's clamp, index and interpolation over that level's LUT. NaN is
/// transparent.
RESOCT_FN vec4 resoct_step_lut_lookup(uint slot, uint level, uint level_count, float v) {
  if (isnan(v)) return vec4(0.0f);
  float x = clamp(v, 0.0f, 1.0f) * float(RESOCT_TF_LUT_SIZE - 1u);
  uint i0 = min(uint(x), RESOCT_TF_LUT_SIZE - 2u);
  float f = x - float(i0);
  uint base = (slot * level_count + level) * RESOCT_TF_LUT_SIZE;
  return mix(resoct_read_step_lut(base + i0), resoct_read_step_lut(base + i0 + 1u), f);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_STEP_LUT_GLSL_H
