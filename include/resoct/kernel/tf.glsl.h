// resoct kernel: transfer-function lookup.
//
// Each visible channel slot has a LUT of RESOCT_TF_LUT_SIZE straight-alpha RGBA entries; entry i
// is the piecewise-linear transfer function at the normalized value i / (RESOCT_TF_LUT_SIZE − 1)
// (so both ends are exact), and lookups interpolate linearly between entries. Alpha is the
// opacity of one reference step (see composite.glsl.h). Values outside [0, 1] clamp to the ends;
// NaN is transparent.
//
// Accessor the including file must define BEFORE including this header (C++: in namespace
// resoct::kernel or globally; GLSL: at global scope, typically over an SSBO):
//   vec4 resoct_read_tf(uint slot, uint index)   // index < RESOCT_TF_LUT_SIZE
#ifndef RESOCT_KERNEL_TF_GLSL_H
#define RESOCT_KERNEL_TF_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

/// Entries per transfer-function LUT (one 16 KiB vec4 table per channel slot).
RESOCT_CONST(uint, RESOCT_TF_LUT_SIZE, 1024u);

/// Normalized value of a raw voxel value: (raw − lo) / (hi − lo), given 1 / (hi − lo).
RESOCT_FN float resoct_normalize_value(float raw, float range_lo, float inv_range_width) {
  return (raw - range_lo) * inv_range_width;
}

/// Straight-alpha RGBA of normalized value v in channel slot `slot`.
RESOCT_FN vec4 resoct_tf_lookup(uint slot, float v) {
  if (isnan(v)) return vec4(0.0f);
  float x = clamp(v, 0.0f, 1.0f) * float(RESOCT_TF_LUT_SIZE - 1u);
  uint i0 = min(uint(x), RESOCT_TF_LUT_SIZE - 2u);
  float f = x - float(i0);
  return mix(resoct_read_tf(slot, i0), resoct_read_tf(slot, i0 + 1u), f);
}

/// Occupancy bin of a normalized value: floor(v * 32) clamped to [0, 31], as
/// resoct::occupancy_bit over [0, 1]. NaN must be filtered by the caller.
RESOCT_FN uint resoct_occupancy_bin(float v) {
  return min(uint(clamp(v, 0.0f, 1.0f) * 32.0f), 31u);
}

/// Whether a node with normalized value bounds [lo, hi] may render visibly under a transfer
/// function whose visible occupancy mask is `tf_mask` (TransferFunction::visible_mask). It is
/// conservative: it tests whole bins, so it never culls what TransferFunction::visible_in
/// accepts. NaN bounds or lo > hi (no finite values) are invisible.
RESOCT_FN bool resoct_tf_range_visible(uint tf_mask, float lo, float hi) {
  if (isnan(lo) || isnan(hi) || lo > hi) return false;
  uint a = resoct_occupancy_bin(lo);
  uint b = resoct_occupancy_bin(hi);
  uint upto_b = b >= 31u ? 0xFFFFFFFFu : ((1u << (b + 1u)) - 1u);
  uint below_a = (1u << a) - 1u;
  return (tf_mask & upto_b & ~below_a) != 0u;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_TF_GLSL_H
