// resoct kernel: the residency traversal's descent to the node a sample lies in (paper 000
// Alg. 1, thesis Alg. 7.5), one source for C++ and GLSL. The march (traverse.glsl.h) calls it at
// each decision of residency mode; it keeps the node, its box and classes, and the path of the
// last descent, which the next descent reuses down to the deepest node both share. See
// docs/rendering.md ("Traversal", "Visible subtrees").
//
// Accessors: resoct_read_node, resoct_read_slot, resoct_read_depth,
// resoct_read_visible_subtrees, resoct_report_node_request (see traverse.glsl.h).
#ifndef RESOCT_KERNEL_RESIDENCY_DESCENT_GLSL_H
#define RESOCT_KERNEL_RESIDENCY_DESCENT_GLSL_H

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/effect_sample.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/node_class.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"

RESOCT_KERNEL_BEGIN

/// A ray's residency-mode node: the classification of the last traversal node, reused while
/// samples stay in its box, and the path of the descent that found it.
struct ResoctDescent {
  uint node;    // flat node index; RESOCT_NONE_U: none (also set when a slice or lens segment
                // changes the bank), which drops the path too
  uvec3 coord;  // coordinates at `depth` of the traversal node
  uint depth;   // the traversal depth the node was found for
  ivec3 lo;     // level-0 box [lo, hi) in which the classification holds
  ivec3 hi;
  uint empty;  // channels found empty
  uint homog;  // channels found homogeneous
  // The depth of the node at which every live channel was empty (RESOCT_NONE_U: none): the
  // sample lies in an empty node of that depth.
  uint skip_depth;
  // The depth of `node` when it is an ancestor of the traversal node at which the descent
  // stopped because no node below it can be EMPTY for a live channel (resoct_node_full); then
  // its whole box is one visible node, with no descent, classification or run inside it.
  // RESOCT_NONE_U: the descent reached the traversal node.
  uint full_depth;
};

/// The path of a ray's last descent, which the next one reuses: the descent's own state, which
/// the march never reads (it reads ResoctDescent).
struct ResoctDescentPath {
  // Per depth d in [start_depth, end] the node's local index and the channels found empty down
  // to it; skip = 1 when every channel was empty at `end`.
  uint local[RESOCT_MAX_DEPTHS];
  uint empty[RESOCT_MAX_DEPTHS];
  uint end;
  uint skip;
};

RESOCT_FN void resoct_descent_clear(RESOCT_OUT(ResoctDescent) ds,
                                    RESOCT_OUT(ResoctDescentPath) dp) {
  ds.node = RESOCT_NONE_U;
  ds.coord = uvec3(RESOCT_NONE_U);
  ds.depth = 0u;
  ds.lo = ivec3(0);
  ds.hi = ivec3(0);
  ds.empty = 0u;
  ds.homog = 0u;
  ds.skip_depth = RESOCT_NONE_U;
  ds.full_depth = RESOCT_NONE_U;
  dp.end = RESOCT_NONE_U;
  dp.skip = 0u;
}

/// Whether the sample in level-0 cell `cell` still lies in ds's node at traversal depth
/// `cap_depth`: consecutive samples mostly do, and then need no descent (a box test, no
/// division, no walk).
RESOCT_FN bool resoct_descent_holds(RESOCT_IN(ResoctDescent) ds, uint cap_depth, ivec3 cell) {
  return ds.node != RESOCT_NONE_U && cap_depth == ds.depth && resoct_in_box(cell, ds.lo, ds.hi);
}

/// Brings `ds` to the node of depth `cap_depth` that holds `cell` (the sample's level-0 cell)
/// for the live channels `live` of the n slot-table entries from `bank`, where
/// resoct_descent_holds is false: one descent for all channels in importance order, from below
/// the deepest node it shares with the previous path `dp`. A traversal node whose
/// record is INVALID for a channel that decides is requested (once per node in a row, through
/// `last_node_request`). `fx` carries the projections' running values (their classes follow
/// them along the ray).
RESOCT_FX_FN void resoct_residency_descend(RESOCT_FRAME_IN f, uint bank, uint n, uint live,
                                           uint cap_depth, ivec3 cell, RESOCT_IN(ResoctFxRay) fx,
                                           RESOCT_INOUT(ResoctDescent) ds,
                                           RESOCT_INOUT(ResoctDescentPath) dp,
                                           RESOCT_INOUT(uint) last_node_request,
                                           RESOCT_INOUT(ResoctRayStats) stats) {
  // Plain rendering only stops at full nodes: effects and pre-integration read values or node
  // words whose results the descent's depth could change.
  bool full_stops = true;
  RESOCT_IF_FX(RESOCT_EFFECT_ANY | RESOCT_EFFECT_PREINT) {
    full_stops = false;
  }
  RESOCT_IN(ResoctDepthInfo) Dt = resoct_read_depth(cap_depth);
  uvec3 trav_coord = resoct_node_coord(Dt, cell);
  uvec3 trav_log2 = resoct_depth_count_log2(Dt);
  uvec3 ne = uvec3(Dt.node_extent_x, Dt.node_extent_y, Dt.node_extent_z);
  ds.lo = ivec3(trav_coord * ne);
  ds.hi = ds.lo + ivec3(ne);
  uvec3 prev_coord = ds.coord;
  uint prev_depth = ds.depth;
  ds.coord = trav_coord;
  // Alg. 7.5: one descent for all channels in importance order; a channel empty at a
  // node advances the channel index in the same node. `state` = channels empty so far
  // (always channels 0 .. ci - 1). The descent restarts below the deepest node it
  // shares with the previous descent's path (whose results depend only on that node and
  // its ancestors), except for projection channels, whose class follows the running
  // value along the ray.
  uint reuse_end = ds.node == RESOCT_NONE_U ? RESOCT_NONE_U : dp.end;
  RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
    reuse_end = RESOCT_NONE_U;
  }
  bool on_path = reuse_end != RESOCT_NONE_U;
  ds.depth = cap_depth;
  ds.homog = 0u;
  ds.skip_depth = RESOCT_NONE_U;
  ds.full_depth = RESOCT_NONE_U;
  uint full_depth = RESOCT_NONE_U;
  uint state = 0u;
  uint local = 0u;
  uint d_first = 0u;
  if (on_path && prev_depth == cap_depth) {
    // The deepest depth k of the previous path whose node is also the new node's
    // ancestor (their coordinates agree above that depth's count bits): depths up to k
    // are reused without walking them.
    uvec3 diff = trav_coord ^ prev_coord;
    uint k = reuse_end;
    for (;;) {
      uvec3 sh = trav_log2 - resoct_depth_count_log2(resoct_read_depth(k));
      if ((diff.x >> sh.x) == 0u && (diff.y >> sh.y) == 0u && (diff.z >> sh.z) == 0u) {
        break;
      }
      if (k <= f.start_depth) {
        k = RESOCT_NONE_U;
        break;
      }
      k = k - 1u;
    }
    if (k != RESOCT_NONE_U) {
      state = dp.empty[k];
      local = dp.local[k];
      d_first = k + 1u;
      if (k == reuse_end && dp.skip != 0u) {
        ds.skip_depth = k;
        d_first = cap_depth + 1u;
      }
    }
  }
  for (uint d = d_first; d <= cap_depth; ++d) {
    RESOCT_IN(ResoctDepthInfo) D = resoct_read_depth(d);
    if (d > 0u) {
      local = (local << D.child_shift) |
              resoct_node_child_bits(D, resoct_ancestor_coord(D, trav_coord, trav_log2));
    }
    if (d < f.start_depth) continue;
    if (on_path && d <= reuse_end && dp.local[d] == local) {
      state = dp.empty[d];
      if (d == reuse_end && dp.skip != 0u) {
        ds.skip_depth = d;
        break;
      }
      continue;
    }
    // From here on the path differs from the previous one: drop its deeper entries.
    on_path = false;
    dp.local[d] = local;
    dp.end = d > f.start_depth ? d - 1u : RESOCT_NONE_U;
    dp.skip = 0u;
    if (d == cap_depth) break;  // the traversal node: classified below
    stats.nodes = stats.nodes + 1u;
    uint nd = D.first_node + local;
    uint ci = uint(bitCount(state));
    while (ci < n) {
      bool empty = ((live >> ci) & 1u) == 0u;
      if (!empty) {
        uint cls;
        RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
          cls = resoct_mode_node_class_carried(nd, d, f.start_depth, resoct_read_slot(bank + ci),
                                               f.node_slot_count, fx.proj[ci]);
        }
        else {
          cls = resoct_node_class_carried(nd, d, f.start_depth, resoct_read_slot(bank + ci),
                                          f.node_slot_count);
        }
        empty = cls == RESOCT_NODE_CLASS_EMPTY;
      }
      if (!empty) break;
      state = state | (1u << ci);
      ci = ci + 1u;
    }
    dp.empty[d] = state;
    dp.end = d;
    dp.skip = ci == n ? 1u : 0u;
    if (ci == n) {
      ds.skip_depth = d;
      break;
    }
    if (full_stops) {
      // Channel ci is visible here; when it and every later live channel are full, no
      // node below can be skipped for them: this node is the traversal node. Full is
      // the frame's visible-subtree bit (every node below checked on the host), or the
      // node's own record when its range proves it.
      uint visible_below = resoct_read_visible_subtrees(nd);
      bool full = true;
      for (uint c = ci; c < n && full; ++c) {
        if (((live >> c) & 1u) != 0u) {
          uint e = bank + c;
          full = (e < RESOCT_MAX_SLOTS && ((visible_below >> e) & 1u) != 0u) ||
                 resoct_node_full(nd, resoct_read_slot(e), f.node_slot_count);
        }
      }
      if (full) {
        full_depth = d;
        break;
      }
    }
  }
  ds.empty = state;
  if (full_depth != RESOCT_NONE_U) {
    RESOCT_IN(ResoctDepthInfo) Df = resoct_read_depth(full_depth);
    ds.node = Df.first_node + local;
    uvec3 fne = uvec3(Df.node_extent_x, Df.node_extent_y, Df.node_extent_z);
    ds.lo = ivec3(resoct_ancestor_coord(Df, trav_coord, trav_log2) * fne);
    ds.hi = ds.lo + ivec3(fne);
    ds.full_depth = full_depth;
  } else if (ds.skip_depth == RESOCT_NONE_U) {
    // The remaining channels at the traversal node. A node whose own record is INVALID
    // is requested; its class is carried down from the nearest ancestor with metadata
    // (not empty when there is none).
    ds.node = Dt.first_node + local;
    stats.nodes = stats.nodes + 1u;
    uint invalid = 0u;
    for (uint c = uint(bitCount(state)); c < n; ++c) {
      if (((live >> c) & 1u) == 0u) {
        ds.empty = ds.empty | (1u << c);
        continue;
      }
      RESOCT_IN(ResoctSlotInfo) sc = resoct_read_slot(bank + c);
      uint cls;
      RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
        cls = resoct_mode_node_class(ds.node, sc, f.node_slot_count, fx.proj[c]);
      }
      else {
        cls = resoct_node_class(ds.node, sc, f.node_slot_count);
      }
      if (cls == RESOCT_NODE_CLASS_INVALID) {
        invalid = invalid | (1u << c);
        RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
          cls = resoct_mode_node_class_carried(ds.node, cap_depth, f.start_depth, sc,
                                               f.node_slot_count, fx.proj[c]);
        }
        else {
          cls = resoct_node_class_carried(ds.node, cap_depth, f.start_depth, sc, f.node_slot_count);
        }
        // A homogeneous ancestor's value is only known at the ancestor: read it there.
        if (cls == RESOCT_NODE_CLASS_HOMOGENEOUS) cls = RESOCT_NODE_CLASS_VISIBLE;
      }
      if (cls == RESOCT_NODE_CLASS_EMPTY) ds.empty = ds.empty | (1u << c);
      if (cls == RESOCT_NODE_CLASS_HOMOGENEOUS) ds.homog = ds.homog | (1u << c);
    }
    uint all = n >= 32u ? 0xFFFFFFFFu : ((1u << n) - 1u);
    if (ds.empty == all) {
      ds.skip_depth = cap_depth;
    } else if ((invalid >> uint(findLSB(~ds.empty))) != 0u && ds.node != last_node_request) {
      // Requested when an INVALID channel is at or after the first channel that is
      // not empty here: channels before it were settled by their ancestors' records.
      last_node_request = ds.node;
      resoct_report_node_request(ds.node);
      stats.requests = stats.requests + 1u;
    }
  } else {
    RESOCT_IN(ResoctDepthInfo) Dk = resoct_read_depth(ds.skip_depth);
    ds.node = Dk.first_node + dp.local[ds.skip_depth];
  }
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_RESIDENCY_DESCENT_GLSL_H
