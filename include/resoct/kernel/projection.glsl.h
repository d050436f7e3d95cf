// resoct kernel: node classification for the per-channel modes that are not emission-absorption.
//
// MIP and AIP channels (maximum / average intensity projection) accumulate the channel's
// normalized value, clamped to [0, 1], along the whole ray; the transfer function is applied to
// the result. Their transfer function says nothing about which samples matter, so their nodes
// are classified by value instead: a node is EMPTY (skippable) for MIP only when its maximum
// cannot beat the ray's running maximum, and for AIP only when its maximum is 0 (every clamped
// value is 0, so skipping adds exactly what sampling would). The node maximum is quantized up,
// so both tests are conservative. Isosurface channels use the ordinary classification with the
// slot's visible range set to the isovalues' hull (frame_tables.cpp), which keeps a node exactly
// when a crossing may lie in it.
//
// Accessors: resoct_read_node, resoct_read_depth (see traverse.glsl.h).
#ifndef RESOCT_KERNEL_PROJECTION_GLSL_H
#define RESOCT_KERNEL_PROJECTION_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/node_class.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_FN bool resoct_is_projection(RESOCT_IN(ResoctSlotInfo) s) {
  return s.mode == RESOCT_CHANNEL_MIP || s.mode == RESOCT_CHANNEL_AIP;
}

/// Largest 16-bit node maximum that cannot change a projection whose running value is `beat`.
RESOCT_FN uint resoct_projection_threshold16(RESOCT_IN(ResoctSlotInfo) s, float beat) {
  if (s.mode == RESOCT_CHANNEL_AIP) return 0u;
  return uint(floor(clamp(beat, 0.0f, 1.0f) * float(RESOCT_QUANT_MAX)));
}

/// Class of a MIP/AIP channel at a node from its own record (see the file comment).
RESOCT_FN uint resoct_projection_node_class(uint node, RESOCT_IN(ResoctSlotInfo) s, uint node_slots,
                                            uint threshold16) {
  uint base = resoct_node_base(node, s.slot, node_slots);
  uint state = resoct_node_state(resoct_read_node(base + RESOCT_NODE_FLAGS));
  if (state == RESOCT_NODE_INVALID) return RESOCT_NODE_CLASS_INVALID;
  uint minmax = resoct_read_node(base + RESOCT_NODE_MINMAX);
  if (resoct_node_range_empty(minmax) || resoct_node_max16(minmax) <= threshold16) {
    return RESOCT_NODE_CLASS_EMPTY;
  }
  if (state == RESOCT_NODE_VALID && resoct_node_min16(minmax) == resoct_node_max16(minmax)) {
    return RESOCT_NODE_CLASS_HOMOGENEOUS;
  }
  return RESOCT_NODE_CLASS_VISIBLE;
}

/// As resoct_node_class_carried, for any channel mode: projection channels by value, the others
/// by their visible range. `beat` is the channel's running projection value.
RESOCT_FN uint resoct_mode_node_class_carried(uint node, uint depth, uint top,
                                              RESOCT_IN(ResoctSlotInfo) s, uint node_slots,
                                              float beat) {
  if (!resoct_is_projection(s)) return resoct_node_class_carried(node, depth, top, s, node_slots);
  uint thr = resoct_projection_threshold16(s, beat);
  uint cls = resoct_projection_node_class(node, s, node_slots, thr);
  if (cls != RESOCT_NODE_CLASS_INVALID) return cls;
  uint d = depth;
  uint local = node - resoct_read_depth(d).first_node;
  while (cls == RESOCT_NODE_CLASS_INVALID && d > top) {
    local = local >> resoct_read_depth(d).child_shift;
    d = d - 1u;
    cls = resoct_projection_node_class(resoct_read_depth(d).first_node + local, s, node_slots, thr);
  }
  return cls;
}

/// The mode-aware class of a channel at its own node record (no ancestor walk).
RESOCT_FN uint resoct_mode_node_class(uint node, RESOCT_IN(ResoctSlotInfo) s, uint node_slots,
                                      float beat) {
  if (!resoct_is_projection(s)) return resoct_node_class(node, s, node_slots);
  return resoct_projection_node_class(node, s, node_slots, resoct_projection_threshold16(s, beat));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_PROJECTION_GLSL_H
