// resoct kernel: octree node addressing and per-channel node classification for the residency
// traversal (paper 000 Alg. 1, thesis Alg. 7.5), shared by primary rays (traverse.glsl.h) and
// shadow rays (shadow.glsl.h). See docs/rendering.md ("Traversal").
//
// Accessors: resoct_read_node, resoct_read_depth (see traverse.glsl.h).
#ifndef RESOCT_KERNEL_NODE_CLASS_GLSL_H
#define RESOCT_KERNEL_NODE_CLASS_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/sample.glsl.h"

RESOCT_KERNEL_BEGIN

// Node classification of one channel.
RESOCT_CONST(uint, RESOCT_NODE_CLASS_VISIBLE, 0u);
RESOCT_CONST(uint, RESOCT_NODE_CLASS_INVALID, 1u);
RESOCT_CONST(uint, RESOCT_NODE_CLASS_EMPTY, 2u);
RESOCT_CONST(uint, RESOCT_NODE_CLASS_HOMOGENEOUS, 3u);

RESOCT_CONST(uint, RESOCT_NONE_U, 0xFFFFFFFFu);

/// Most depths a layout can have (OctreeLayout::kMaxNodes = 2^31, each depth at least doubles).
RESOCT_CONST(uint, RESOCT_MAX_DEPTHS, 32u);

/// Child bits of a node coordinate at depth D: the low coordinate bit of each split axis, z then
/// y then x with x least significant (OctreeLayout's order).
RESOCT_FN uint resoct_node_child_bits(RESOCT_IN(ResoctDepthInfo) D, uvec3 c) {
  uint bits = 0u;
  uint shift = 0u;
  if (D.split_x != 0u) {
    bits = c.x & 1u;
    shift = 1u;
  }
  if (D.split_y != 0u) {
    bits = bits | ((c.y & 1u) << shift);
    shift = shift + 1u;
  }
  if (D.split_z != 0u) bits = bits | ((c.z & 1u) << shift);
  return bits;
}

/// Coordinates of the node at depth D containing a cell inside the volume.
RESOCT_FN uvec3 resoct_node_coord(RESOCT_IN(ResoctDepthInfo) D, ivec3 cell) {
  uvec3 c = uvec3(cell) / uvec3(D.node_extent_x, D.node_extent_y, D.node_extent_z);
  return min(c, uvec3(D.count_x - 1u, D.count_y - 1u, D.count_z - 1u));
}

/// Classifies one channel at a node from its own metadata record.
RESOCT_FN uint resoct_node_class(uint node, RESOCT_IN(ResoctSlotInfo) s, uint node_slots) {
  uint base = resoct_node_base(node, s.slot, node_slots);
  uint flags = resoct_read_node(base + RESOCT_NODE_FLAGS);
  uint state = resoct_node_state(flags);
  if (state == RESOCT_NODE_INVALID) return RESOCT_NODE_CLASS_INVALID;
  uint minmax = resoct_read_node(base + RESOCT_NODE_MINMAX);
  if (!resoct_node_range_visible(minmax, s.vis_lo16, s.vis_hi16, s.vis_bins)) {
    return RESOCT_NODE_CLASS_EMPTY;
  }
  if (state == RESOCT_NODE_VALID && resoct_node_min16(minmax) == resoct_node_max16(minmax)) {
    return RESOCT_NODE_CLASS_HOMOGENEOUS;
  }
  return RESOCT_NODE_CLASS_VISIBLE;
}

/// Whether a channel's own record at `node` proves that the descent could find no EMPTY node
/// below it: the record's range [min16, max16] lies inside the transfer function's visible hull
/// and every occupancy bin it spans is visible, so every non-empty sub-range (a descendant's
/// record) passes resoct_node_range_visible. A march may then treat the whole node as one visible
/// node. Where records do not nest (an APPROX record may be too narrow) a descendant could still
/// be EMPTY; its samples are then transparent, so sampling it instead of skipping leaves the image
/// as it is. False for a homogeneous record (VALID, min = max), whose value the traversal uses
/// without sampling.
RESOCT_FN bool resoct_node_full(uint node, RESOCT_IN(ResoctSlotInfo) s, uint node_slots) {
  uint base = resoct_node_base(node, s.slot, node_slots);
  uint state = resoct_node_state(resoct_read_node(base + RESOCT_NODE_FLAGS));
  if (state == RESOCT_NODE_INVALID) return false;
  uint minmax = resoct_read_node(base + RESOCT_NODE_MINMAX);
  if (resoct_node_range_empty(minmax)) return false;
  uint lo = resoct_node_min16(minmax);
  uint hi = resoct_node_max16(minmax);
  if (lo < s.vis_lo16 || hi > s.vis_hi16) return false;
  if (state == RESOCT_NODE_VALID && lo == hi) return false;
  return (resoct_node_range_bins(minmax) & ~s.vis_bins) == 0u;
}

/// Deepest octree depth whose nodes are at least `dt` long on every axis (smaller nodes cannot
/// skip more than a step), at least `start_depth`. The host stores each depth's shortest side
/// (ResoctDepthInfo.shortest_side), so this is a compare per depth, not three divisions.
RESOCT_FN uint resoct_traversal_depth_for(uint start_depth, uint depth_count, float dt) {
  uint depth = start_depth;
  for (uint d = start_depth + 1u; d < depth_count; ++d) {
    if (resoct_read_depth(d).shortest_side < dt) break;
    depth = d;
  }
  return depth;
}

/// The traversal depth of a primary ray with step dt.
RESOCT_FN uint resoct_traversal_depth(RESOCT_FRAME_IN f, float dt) {
  return resoct_traversal_depth_for(f.start_depth, f.depth_count, dt);
}

/// log2 of the node counts per axis at depth D (counts are powers of two).
RESOCT_FN uvec3 resoct_depth_count_log2(RESOCT_IN(ResoctDepthInfo) D) {
  return uvec3(D.count_log2_x, D.count_log2_y, D.count_log2_z);
}

/// Coordinates at depth D of the ancestor of the node with coordinates `deep` at a deeper depth
/// whose count_log2 is `deep_log2`: node boxes nest exactly, so this is a shift, not a division.
RESOCT_FN uvec3 resoct_ancestor_coord(RESOCT_IN(ResoctDepthInfo) D, uvec3 deep, uvec3 deep_log2) {
  return deep >> (deep_log2 - resoct_depth_count_log2(D));
}

/// Flat index of the node at depth `depth` whose coordinates are `coord` (count_log2
/// `coord_log2`), built from the root by child bits.
RESOCT_FN uint resoct_node_index(uint depth, uvec3 coord, uvec3 coord_log2) {
  uint local = 0u;
  for (uint d = 1u; d <= depth; ++d) {
    RESOCT_IN(ResoctDepthInfo) D = resoct_read_depth(d);
    local = (local << D.child_shift) |
            resoct_node_child_bits(D, resoct_ancestor_coord(D, coord, coord_log2));
  }
  return resoct_read_depth(depth).first_node + local;
}

/// 1 + the deepest octree depth whose nodes are unions of level L's bricks (each node contains
/// the brick of L at any position inside it); 0 when no depth's are. Nodes and bricks both start
/// at voxel 0, so a node is such a union when its extent is a multiple of the brick's (in level-0
/// voxels); node extents halve or stay from one depth to the next, so these depths are a prefix.
RESOCT_FN uint resoct_brick_depth_end(RESOCT_FRAME_IN f, RESOCT_IN(ResoctLevelInfo) L,
                                      uvec3 brick_size) {
  if (L.node_depth != RESOCT_NONE_U) return L.node_depth + 1u;  // its nodes are the bricks
  // Else no depth's nodes equal the bricks: if the deepest depth's nodes are unions of them,
  // every depth's are.
  RESOCT_IN(ResoctDepthInfo) D = resoct_read_depth(f.depth_count - 1u);
  uvec3 brick0 = brick_size << resoct_level_factor(L);
  uvec3 ne = uvec3(D.node_extent_x, D.node_extent_y, D.node_extent_z);
  return all(equal(ne % brick0, uvec3(0u))) ? f.depth_count : 0u;
}

/// Local index of the neighbour one node along an axis (`step` +1 or -1) of the node with local
/// index `local`, for that axis's bits of the local index at the node's depth
/// (ResoctDepthInfo.axis_bits_*): the axis coordinate is spread over those bits, so the step is an
/// add within them, the carry passing over the other axes' bits. The caller keeps the coordinate
/// inside the depth's node counts (a step past the edge wraps within the bits).
RESOCT_FN uint resoct_node_neighbor_local(uint local, uint axis_bits, int step) {
  uint moved = step > 0 ? ((local | ~axis_bits) + 1u) : ((local & axis_bits) - 1u);
  return (moved & axis_bits) | (local & ~axis_bits);
}

/// The axis bits of depth D for axis `axis` (0 x, 1 y, 2 z).
RESOCT_FN uint resoct_depth_axis_bits(RESOCT_IN(ResoctDepthInfo) D, uint axis) {
  return axis == 0u ? D.axis_bits_x : (axis == 1u ? D.axis_bits_y : D.axis_bits_z);
}

/// Class of a channel at the node of depth `depth`: its own record if it has metadata, else that
/// of the nearest ancestor (down to `top`) that has, since a parent's record covers its children;
/// INVALID when none has. Walks up by shifting the node's local index (a parent's local index is
/// the child's without its child bits), so the walk is O(depth), not O(depth^2).
RESOCT_FN uint resoct_node_class_carried(uint node, uint depth, uint top,
                                         RESOCT_IN(ResoctSlotInfo) s, uint node_slots) {
  uint cls = resoct_node_class(node, s, node_slots);
  if (cls != RESOCT_NODE_CLASS_INVALID) return cls;
  uint d = depth;
  uint local = node - resoct_read_depth(d).first_node;
  while (cls == RESOCT_NODE_CLASS_INVALID && d > top) {
    local = local >> resoct_read_depth(d).child_shift;
    d = d - 1u;
    cls = resoct_node_class(resoct_read_depth(d).first_node + local, s, node_slots);
  }
  return cls;
}

/// Per axis, how far inside a node (in level-0 voxels) the trilinear support of a sample of a
/// level with factors `factor_log2` stays within the node dilated by one level-0 voxel, the box
/// node metadata describes: half a level voxel, 2^(f-1), for f >= 1, and 0 at level 0. Level-l
/// voxel i averages level-0 voxels [i 2^f, (i + 1) 2^f), and a sample at level-0 x interpolates
/// level voxels floor(x / 2^f - 1/2) and the next; for node faces on the level's voxel grid
/// (nodes span at least two level voxels) those lie inside the dilated node exactly when x is at
/// least 2^(f-1) from both faces. docs/rendering.md "Exact culling".
RESOCT_FN int resoct_half_level_voxel(uint factor_log2) {
  return factor_log2 == 0u ? 0 : int(1u << (factor_log2 - 1u));
}
RESOCT_FN ivec3 resoct_culling_margin(uvec3 factor_log2) {
  return ivec3(resoct_half_level_voxel(factor_log2.x), resoct_half_level_voxel(factor_log2.y),
               resoct_half_level_voxel(factor_log2.z));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_NODE_CLASS_GLSL_H
