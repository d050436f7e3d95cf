// resoct kernel: runs of residency-octree nodes of one class along a ray.
//
// A residency decision of the march (traverse.glsl.h) classifies the node a sample lies in. The
// nodes the ray enters next at the same depth often have the same class: a skip then goes on
// through the empty ones, and a visible node's segment takes in the visible ones, so that
// entering them costs no decision (docs/rendering.md "Segments", runs of nodes).
//
// Accessors the including file must define BEFORE including this header: resoct_read_node,
// resoct_read_slot, resoct_read_depth (see traverse.glsl.h).
#ifndef RESOCT_KERNEL_NODE_RUN_GLSL_H
#define RESOCT_KERNEL_NODE_RUN_GLSL_H

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/node_class.glsl.h"
#include "resoct/kernel/ray.glsl.h"

RESOCT_KERNEL_BEGIN

/// Most nodes beyond the current one that one residency decision classifies ahead along the ray.
RESOCT_CONST(uint, RESOCT_NODE_RUN_LENGTH, 8u);

/// Whether every live channel's own record at `node` has the class `cls` (EMPTY or VISIBLE).
RESOCT_FN bool resoct_node_class_all(RESOCT_FRAME_IN f, uint bank, uint n, uint live, uint node,
                                     uint cls) {
  for (uint c = 0u; c < n; ++c) {
    if (((live >> c) & 1u) == 0u) continue;
    if (resoct_node_class(node, resoct_read_slot(bank + c), f.node_slot_count) != cls) {
      return false;
    }
  }
  return true;
}

/// The end of a run of nodes of one class along the ray. The run starts at the node `node` of
/// depth `depth` with coordinates `coord` and level-0 corner `lo`, which holds the sample at (cell,
/// frac) and which the ray leaves at `node_end` (t relative to the sample); the nodes the ray
/// enters next continue it while every live channel's own record has the class `cls`: EMPTY (a
/// skip goes on through them) or VISIBLE (crossing into them is no decision). A node's metadata
/// covers its subtree, so a node's own class for a channel is the class the descent would find
/// there (no ancestor of a visible node is empty for the channel; an empty node's descendants are
/// all empty). The run stops at the first other node (one without metadata included), at the
/// volume's faces or the integer box [box_lo, box_hi), after RESOCT_NODE_RUN_LENGTH nodes, and
/// where the ray leaves a node through an edge or a corner. Which face the ray leaves through is
/// decided by comparing products, which both backends round alike (a quotient may differ in its
/// last bit on a device), so that the nodes visited are the same on every backend; the exits
/// themselves are computed from the sample's exact position, as the current node's is (`inv_vox`:
/// the reciprocal of `dir_vox`, resoct_ray_inverse).
RESOCT_FN float resoct_node_run_end(RESOCT_FRAME_IN f, uint bank, uint n, uint live, uint cls,
                                    uint depth, uint node, uvec3 coord, ivec3 lo, ivec3 cell,
                                    vec3 frac, vec3 dir_vox, vec3 inv_vox, float node_end,
                                    ivec3 box_lo, ivec3 box_hi,
                                    RESOCT_INOUT(ResoctRayStats) stats) {
  RESOCT_IN(ResoctDepthInfo) D = resoct_read_depth(depth);
  ivec3 ne = ivec3(D.node_extent_x, D.node_extent_y, D.node_extent_z);
  uvec3 count = uvec3(D.count_x, D.count_y, D.count_z);
  uint local = node - D.first_node;
  vec3 ad = abs(dir_vox);
  // The sample's position relative to the current node's corner; a step changes one axis's
  // component, recomputed from the integers (the same float as resoct_relative_origin).
  vec3 rel = resoct_relative_origin(cell, frac, lo);
  // The last node found to continue the run (its corner): the run's end is its exit, since the
  // exits of consecutive nodes along the ray never decrease (each is a minimum of per-axis
  // products, and a step only moves one axis's far face further along the ray).
  ivec3 run_lo = lo;
  bool ran = false;
  for (uint i = 0u; i < RESOCT_NODE_RUN_LENGTH; ++i) {
    // Distance to the far face per axis, in level-0 voxels (infinite where the ray is parallel):
    // the exit along an axis is dist / |dir|, compared across axes as dist_a * |dir_b|.
    vec3 dist = vec3(dir_vox.x > 0.0f ? float(ne.x) - rel.x : rel.x,
                     dir_vox.y > 0.0f ? float(ne.y) - rel.y : rel.y,
                     dir_vox.z > 0.0f ? float(ne.z) - rel.z : rel.z);
    bool px = ad.x < RESOCT_RAY_PARALLEL_EPS;
    bool py = ad.y < RESOCT_RAY_PARALLEL_EPS;
    bool pz = ad.z < RESOCT_RAY_PARALLEL_EPS;
    RESOCT_PRECISE float xy = dist.x * ad.y;
    RESOCT_PRECISE float yx = dist.y * ad.x;
    RESOCT_PRECISE float xz = dist.x * ad.z;
    RESOCT_PRECISE float zx = dist.z * ad.x;
    RESOCT_PRECISE float yz = dist.y * ad.z;
    RESOCT_PRECISE float zy = dist.z * ad.y;
    // Axis a is the unique first exit when its exit is strictly before each other axis's.
    bool x_first = !px && (py || xy < yx) && (pz || xz < zx);
    bool y_first = !py && (px || yx < xy) && (pz || yz < zy);
    bool z_first = !pz && (px || zx < xz) && (py || zy < yz);
    if (!x_first && !y_first && !z_first) break;
    uint axis = x_first ? 0u : (y_first ? 1u : 2u);
    float d = axis == 0u ? dir_vox.x : (axis == 1u ? dir_vox.y : dir_vox.z);
    int dstep = d > 0.0f ? 1 : -1;
    // Unsigned: stepping below 0 wraps past the count.
    coord[axis] = uint(int(coord[axis]) + dstep);
    if (coord[axis] >= count[axis]) break;
    local = resoct_node_neighbor_local(local, resoct_depth_axis_bits(D, axis), dstep);
    lo[axis] = lo[axis] + dstep * ne[axis];
    if (any(lessThan(lo, box_lo)) || any(greaterThan(lo + ne, box_hi))) break;
    stats.nodes = stats.nodes + 1u;
    if (!resoct_node_class_all(f, bank, n, live, D.first_node + local, cls)) break;
    run_lo = lo;
    ran = true;
    rel[axis] = resoct_int_difference(cell[axis], lo[axis]) + frac[axis];
  }
  if (!ran) return node_end;
  return max(node_end, resoct_box_exit_t(cell, frac, inv_vox, run_lo, run_lo + ne));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_NODE_RUN_GLSL_H
