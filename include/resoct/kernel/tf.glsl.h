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

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_TF_GLSL_H
