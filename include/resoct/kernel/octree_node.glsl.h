// resoct single-source kernel: the residency-octree node record (see docs/residency-octree.md).
//
// Every (node, slot) pair owns RESOCT_NODE_WORDS consecutive uint words, node-major:
//   base = (node * slot_count + slot) * RESOCT_NODE_WORDS
//   +0 residency  bit l set = at least one brick of level l of this slot overlapping the node is
//                 resident (partial residency); a full word, so 32 levels fit
//   +1 min/max    bits 16..31: max quantized UP to 16 bits over the slot's ValueRange;
//                 bits 0..15: 0xffff - (min quantized DOWN). The min is stored inverted so that an
//                 all-zero word means "no values" (min > max) and the union of two records is the
//                 per-half maximum.
//   +2 occupancy  32 value bins over the ValueRange (resoct::occupancy_bit), bit b set when some
//                 value may fall into bin b
//   +3 flags      bits 0..1 state (INVALID, VALID, APPROX), bits 8..12 the brick level an APPROX
//                 record was derived from
// An all-zero record is INVALID, unmapped and empty: untouched nodes cost nothing to initialize.
// UNKNOWN is not stored: traversal descends from the root and carries the nearest VALID/APPROX
// ancestor; RESOCT_NODE_UNKNOWN is what a lookup returns when no node on the path is valid.
#ifndef RESOCT_KERNEL_OCTREE_NODE_GLSL_H
#define RESOCT_KERNEL_OCTREE_NODE_GLSL_H

#include "common.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_CONST(uint, RESOCT_NODE_WORDS, 4u);
RESOCT_CONST(uint, RESOCT_NODE_RESIDENCY, 0u);
RESOCT_CONST(uint, RESOCT_NODE_MINMAX, 1u);
RESOCT_CONST(uint, RESOCT_NODE_OCCUPANCY, 2u);
RESOCT_CONST(uint, RESOCT_NODE_FLAGS, 3u);

// Metadata states (flags bits 0..1).
RESOCT_CONST(uint, RESOCT_NODE_INVALID, 0u);  // not known yet: use the nearest valid ancestor
RESOCT_CONST(uint, RESOCT_NODE_VALID, 1u);    // conservative: true values lie within min/max
RESOCT_CONST(uint, RESOCT_NODE_APPROX, 2u);   // estimated from a coarse brick, may be too narrow
RESOCT_CONST(uint, RESOCT_NODE_STATE_MASK, 3u);
RESOCT_CONST(uint, RESOCT_NODE_APPROX_LEVEL_SHIFT, 8u);
RESOCT_CONST(uint, RESOCT_NODE_APPROX_LEVEL_MASK, 31u);
// Result of an ancestor lookup that found no node with metadata.
RESOCT_CONST(uint, RESOCT_NODE_UNKNOWN, 0xffffffffu);

RESOCT_CONST(uint, RESOCT_QUANT_MAX, 65535u);

RESOCT_FN uint resoct_node_base(uint node, uint slot, uint slot_count) {
  return (node * slot_count + slot) * RESOCT_NODE_WORDS;
}

RESOCT_FN uint resoct_node_pack_minmax(uint min16, uint max16) {
  return (max16 << 16u) | (RESOCT_QUANT_MAX - min16);
}
RESOCT_FN uint resoct_node_min16(uint minmax) {
  return RESOCT_QUANT_MAX - (minmax & 0xffffu);
}
RESOCT_FN uint resoct_node_max16(uint minmax) {
  return minmax >> 16u;
}
// True when the record holds no values at all (only NaN, or nothing known yet).
RESOCT_FN bool resoct_node_range_empty(uint minmax) {
  return resoct_node_min16(minmax) > resoct_node_max16(minmax);
}
// Union of two min/max words: per-half maximum thanks to the inverted min.
RESOCT_FN uint resoct_node_merge_minmax(uint a, uint b) {
  uint hi = max(a >> 16u, b >> 16u);
  uint lo = max(a & 0xffffu, b & 0xffffu);
  return (hi << 16u) | lo;
}

RESOCT_FN uint resoct_node_state(uint flags) {
  return flags & RESOCT_NODE_STATE_MASK;
}
RESOCT_FN uint resoct_node_approx_level(uint flags) {
  return (flags >> RESOCT_NODE_APPROX_LEVEL_SHIFT) & RESOCT_NODE_APPROX_LEVEL_MASK;
}
RESOCT_FN uint resoct_node_make_flags(uint state, uint approx_level) {
  return (state & RESOCT_NODE_STATE_MASK) |
         ((approx_level & RESOCT_NODE_APPROX_LEVEL_MASK) << RESOCT_NODE_APPROX_LEVEL_SHIFT);
}
RESOCT_FN bool resoct_node_has_metadata(uint flags) {
  return resoct_node_state(flags) != RESOCT_NODE_INVALID;
}

RESOCT_FN bool resoct_node_partially_mapped(uint residency, uint level) {
  return ((residency >> level) & 1u) != 0u;
}
// Nearest resident level coarser than `level` (larger index), or -1.
RESOCT_FN int resoct_node_next_coarser(uint residency, uint level) {
  uint above = level >= 31u ? 0u : (residency & ~((2u << level) - 1u));
  return findLSB(above);
}
// Nearest resident level finer than `level` (smaller index), or -1.
RESOCT_FN int resoct_node_next_finer(uint residency, uint level) {
  uint below = residency & ((1u << level) - 1u);
  return findMSB(below);
}

// Whether a record's values may be visible under a transfer function whose visible values are
// [vis_lo16, vis_hi16] (quantized like the record) and occupy the bins in vis_bins. False only
// when both tests prove every value of the node invisible.
RESOCT_FN bool resoct_node_may_be_visible(uint minmax, uint occupancy, uint vis_lo16, uint vis_hi16,
                                          uint vis_bins) {
  if (resoct_node_range_empty(minmax)) return false;
  if (resoct_node_min16(minmax) > vis_hi16 || resoct_node_max16(minmax) < vis_lo16) return false;
  return (occupancy & vis_bins) != 0u;
}

/// Occupancy bins spanned by a record's [min16, max16]: bin k holds normalized values
/// [k / 32, (k + 1) / 32), i.e. unorm16 values u with u >> 11 == k (as resoct_occupancy_bin).
RESOCT_FN uint resoct_node_range_bins(uint minmax) {
  uint a = resoct_node_min16(minmax) >> 11u;
  uint b = resoct_node_max16(minmax) >> 11u;
  uint upto_b = b >= 31u ? 0xFFFFFFFFu : ((1u << (b + 1u)) - 1u);
  return upto_b & ~((1u << a) - 1u);
}

/// Exact culling: whether any value a sample inside the record's box can take may be visible.
/// A trilinear sample (of any level: coarser voxels average finer ones) lies between the minimum
/// and the maximum of the voxels it interpolates, and every value between them can occur, so the
/// test is the whole range [min16, max16] against the transfer function's visible hull and bins,
/// never the occupancy bins (values between two occupied bins are not occupied, yet sampled).
RESOCT_FN bool resoct_node_range_visible(uint minmax, uint vis_lo16, uint vis_hi16, uint vis_bins) {
  if (resoct_node_range_empty(minmax)) return false;
  if (resoct_node_min16(minmax) > vis_hi16 || resoct_node_max16(minmax) < vis_lo16) return false;
  return (resoct_node_range_bins(minmax) & vis_bins) != 0u;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_OCTREE_NODE_GLSL_H
