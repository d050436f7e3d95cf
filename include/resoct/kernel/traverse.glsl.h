// resoct kernel: the per-ray traversal of all three render modes (paper 000 Alg. 1, thesis
// Alg. 7.1-7.5), one source for C++ and GLSL. See docs/rendering.md ("Traversal").
//
// Accessors the including file must define BEFORE including this header (C++: in namespace
// resoct::kernel, after including frame.glsl.h for the record types; GLSL: at global scope,
// typically over storage buffers):
//   uint  resoct_read_node(uint index)               octree word (kernel/octree_node.glsl.h)
//   uint  resoct_read_page(uint index)               page-table entry (kernel/page_entry.glsl.h)
//   uint  resoct_read_page_table_offset(uint table)  first entry of (slot, level) table
//   ResoctSlotInfo  resoct_read_slot(uint i)          slot table, importance order
//   ResoctLevelInfo resoct_read_level(uint l)
//   ResoctDepthInfo resoct_read_depth(uint d)
//   float resoct_sample_cache(uint cache_slot, vec3 pos)  raw voxel value, trilinear, pos in
//                                                    padded-brick voxels, centres at i + 0.5
//   void  resoct_report_request(uint device_key)     a missing brick (request_key.glsl.h)
//   void  resoct_report_node_request(uint node)      a node whose metadata is INVALID
//   void  resoct_mark_used(uint cache_slot)          the slot was sampled this frame
//   vec4  resoct_read_tf(uint slot, uint index)      (tf.glsl.h)
//   float resoct_read_level_size_log2(uint level)    (step.glsl.h)
//
// Per ray: the camera ray is clipped to the volume [0, extent) in voxel space relative to the
// exact eye cell; t (box units) runs over segments of length dt (Eq. 8.2-8.3), each sampled at
// its midpoint, whose position is recomputed from the origin as cell + fraction (so rounding is
// relative to the distance from the eye, never to the volume size). Per sample the LOD target
// level comes from the pixel footprint at the sample's view depth, clamped per channel. Skips
// jump to the first grid sample past the exit of an empty node or brick (exit computed in
// node-local coordinates), so skipping changes which samples run but never where they are.
#ifndef RESOCT_KERNEL_TRAVERSE_GLSL_H
#define RESOCT_KERNEL_TRAVERSE_GLSL_H

#include "resoct/kernel/camera_ray.glsl.h"
#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/kernel/sample.glsl.h"
#include "resoct/kernel/segments.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

// Node classification of one channel.
RESOCT_CONST(uint, RESOCT_NODE_CLASS_VISIBLE, 0u);
RESOCT_CONST(uint, RESOCT_NODE_CLASS_INVALID, 1u);
RESOCT_CONST(uint, RESOCT_NODE_CLASS_EMPTY, 2u);
RESOCT_CONST(uint, RESOCT_NODE_CLASS_HOMOGENEOUS, 3u);

RESOCT_CONST(uint, RESOCT_NONE_U, 0xFFFFFFFFu);

RESOCT_FN void resoct_stats_clear(RESOCT_OUT(ResoctRayStats) st) {
  st.samples = 0u;
  st.nodes = 0u;
  st.brick_accesses = 0u;
  st.iterations = 0u;
  st.cap_hits = 0u;
  st.requests = 0u;
  st.skipped = 0.0f;
  st.marched = 0.0f;
}

/// Child bits of a node coordinate at depth D: the low coordinate bit of each split axis, z then
/// y then x with x least significant (OctreeLayout's order).
RESOCT_FN uint resoct_node_child_bits(ResoctDepthInfo D, uvec3 c) {
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
RESOCT_FN uvec3 resoct_node_coord(ResoctDepthInfo D, ivec3 cell) {
  uvec3 c = uvec3(cell) / uvec3(D.node_extent_x, D.node_extent_y, D.node_extent_z);
  return min(c, uvec3(D.count_x - 1u, D.count_y - 1u, D.count_z - 1u));
}

/// Classifies one channel at a node from its own metadata record.
RESOCT_FN uint resoct_node_class(uint node, ResoctSlotInfo s, uint node_slots) {
  uint base = resoct_node_base(node, s.slot, node_slots);
  uint flags = resoct_read_node(base + RESOCT_NODE_FLAGS);
  uint state = resoct_node_state(flags);
  if (state == RESOCT_NODE_INVALID) return RESOCT_NODE_CLASS_INVALID;
  uint minmax = resoct_read_node(base + RESOCT_NODE_MINMAX);
  uint occupancy = resoct_read_node(base + RESOCT_NODE_OCCUPANCY);
  if (!resoct_node_may_be_visible(minmax, occupancy, s.vis_lo16, s.vis_hi16, s.vis_bins)) {
    return RESOCT_NODE_CLASS_EMPTY;
  }
  if (state == RESOCT_NODE_VALID && resoct_node_min16(minmax) == resoct_node_max16(minmax)) {
    return RESOCT_NODE_CLASS_HOMOGENEOUS;
  }
  return RESOCT_NODE_CLASS_VISIBLE;
}

/// Deepest octree depth whose nodes are at least one step long on every axis (smaller nodes
/// cannot skip more than a step), at least the start depth.
RESOCT_FN uint resoct_traversal_depth(ResoctFrame f, float dt) {
  uint depth = f.start_depth;
  for (uint d = f.start_depth + 1u; d < f.depth_count; ++d) {
    ResoctDepthInfo D = resoct_read_depth(d);
    float sx = float(D.node_extent_x) / f.voxels_per_box_x;
    float sy = float(D.node_extent_y) / f.voxels_per_box_y;
    float sz = float(D.node_extent_z) / f.voxels_per_box_z;
    if (min(sx, min(sy, sz)) < dt) break;
    depth = d;
  }
  return depth;
}

/// log2 of the node counts per axis at depth D (counts are powers of two).
RESOCT_FN uvec3 resoct_depth_count_log2(ResoctDepthInfo D) {
  return uvec3(uint(findMSB(D.count_x)), uint(findMSB(D.count_y)), uint(findMSB(D.count_z)));
}

/// Coordinates at depth D of the ancestor of the node with coordinates `deep` at a deeper depth
/// whose count_log2 is `deep_log2`: node boxes nest exactly, so this is a shift, not a division.
RESOCT_FN uvec3 resoct_ancestor_coord(ResoctDepthInfo D, uvec3 deep, uvec3 deep_log2) {
  return deep >> (deep_log2 - resoct_depth_count_log2(D));
}

/// Flat index of the node at depth `depth` whose coordinates are `coord` (count_log2
/// `coord_log2`), built from the root by child bits.
RESOCT_FN uint resoct_node_index(uint depth, uvec3 coord, uvec3 coord_log2) {
  uint local = 0u;
  for (uint d = 1u; d <= depth; ++d) {
    ResoctDepthInfo D = resoct_read_depth(d);
    local = (local << D.child_shift) |
            resoct_node_child_bits(D, resoct_ancestor_coord(D, coord, coord_log2));
  }
  return resoct_read_depth(depth).first_node + local;
}

/// Class of a channel at the node of depth `depth` on the path to (coord, coord_log2): its own
/// record if it has metadata, else that of the nearest ancestor (down to `top`) that has, since a
/// parent's record covers its children; INVALID when none has.
RESOCT_FN uint resoct_node_class_carried(uint node, uint depth, uint top, uvec3 coord,
                                         uvec3 coord_log2, ResoctSlotInfo s, uint node_slots) {
  uint cls = resoct_node_class(node, s, node_slots);
  uint d = depth;
  while (cls == RESOCT_NODE_CLASS_INVALID && d > top) {
    d = d - 1u;
    ResoctDepthInfo D = resoct_read_depth(d);
    cls = resoct_node_class(resoct_node_index(d, resoct_ancestor_coord(D, coord, coord_log2),
                                              resoct_depth_count_log2(D)),
                            s, node_slots);
  }
  return cls;
}

/// Renders one pixel: the premultiplied colour over the background. `stats` receives the ray's
/// counters.
RESOCT_FN vec4 resoct_render_pixel(ResoctFrame f, uint px, uint py,
                                   RESOCT_OUT(ResoctRayStats) stats) {
  resoct_stats_clear(stats);
  vec4 background = vec4(f.background_r, f.background_g, f.background_b, f.background_a);
  vec4 acc = vec4(0.0f);

  // Channels whose transfer function is invisible everywhere never contribute: drop them in
  // every mode (no samples, no requests).
  uint n = min(f.slot_count, RESOCT_MAX_SLOTS);
  uint live = 0u;
  for (uint i = 0u; i < n; ++i) {
    if (resoct_read_slot(i).vis_bins != 0u) live = live | (1u << i);
  }
  if (live == 0u && f.slice_count == 0u) return resoct_over_background(acc, background);

  vec3 dir_box;
  ivec3 o_cell;
  vec3 o_frac;
  resoct_camera_ray(f, px, py, dir_box, o_cell, o_frac);
  vec3 dir_vox = dir_box * resoct_frame_voxels_per_box(f);

  // Volume interval relative to the origin cell: exact integer box corners.
  vec3 vol_lo = vec3(-o_cell);
  vec3 vol_hi = vec3(ivec3(int(f.extent_x), int(f.extent_y), int(f.extent_z)) - o_cell);
  vec2 tv = resoct_ray_box(o_frac, dir_vox, vol_lo, vol_hi);
  float t = max(tv.x, 0.0f);
  float t_exit = tv.y;
  if (!(t < t_exit)) return resoct_over_background(acc, background);

  vec3 finest = vec3(f.finest_voxel_x, f.finest_voxel_y, f.finest_voxel_z);
  float dt = resoct_step_size(dir_box, finest, f.step_scale, f.min_step);
  uint trav_depth = resoct_traversal_depth(f, dt);
  ResoctSampleParams sp = resoct_sample_params(f);
  ResoctDepthInfo trav_info = resoct_read_depth(trav_depth);
  uvec3 trav_log2 = resoct_depth_count_log2(trav_info);

  uint last_key[RESOCT_MAX_SLOTS];
  for (uint i = 0u; i < RESOCT_MAX_SLOTS; ++i) last_key[i] = RESOCT_REQUEST_KEY_NONE;
  uint last_node_request = RESOCT_NONE_U;

  // Residency mode: classification of the last traversal node, reused while samples stay in it.
  uint cached_node = RESOCT_NONE_U;
  uvec3 cached_coord = uvec3(RESOCT_NONE_U);
  uint cached_empty = 0u;
  uint cached_homog = 0u;
  uint cached_skip_depth = RESOCT_NONE_U;

  // The march ends when less than RESOCT_SEGMENT_EPS of a step remains: such a sliver adds no
  // visible opacity, and its existence would hinge on the last ulp of t_exit, which differs
  // between host and device division and would make the backends' sample counts disagree.
  // Slices and lens (kernel/segments.glsl.h): t_exit is the end of the current segment; at it,
  // resoct_segment_advance composites slices and opens the next segment (bank, live channels).
  ResoctSegments segs = resoct_segments_none(live);
  uint bank = 0u;  // slot-table bank of the current segment
  if (f.slice_count != 0u || f.lens_enabled != 0u) {
    resoct_segments_begin(f, segs, o_cell, o_frac, dir_vox, t, t_exit);
    t_exit = t;
  }
  while (t_exit - t > RESOCT_SEGMENT_EPS * dt ||
         (segs.enabled != 0u &&
          resoct_segment_advance(f, segs, o_cell, o_frac, dir_box, dir_vox, dt, t, t_exit, acc,
                                 live, bank, cached_node, cached_coord, stats))) {
    if (stats.iterations >= f.max_iterations) {
      stats.cap_hits = 1u;
      break;
    }
    stats.iterations = stats.iterations + 1u;
    float seg = resoct_segment_length(t, dt, t_exit);
    float tm = t + 0.5f * seg;
    ivec3 cell;
    vec3 frac;
    resoct_ray_position(o_cell, o_frac, dir_vox, tm, cell, frac);
    resoct_clamp_position(f, cell, frac);

    float budget = resoct_lod_budget_log2(f.footprint_base, f.footprint_slope,
                                          resoct_view_depth(f, dir_box, tm), f.lod_error_px);
    uint lod = resoct_lod_level(budget, f.level_count);

    vec4 weighted;
    float combined;
    resoct_mix_begin(weighted, combined);
    bool any_value = false;
    bool skip = false;
    float skip_exit = RESOCT_RAY_T_INF;

    if (f.mode == RESOCT_MODE_RESIDENCY) {
      uvec3 trav_coord = resoct_node_coord(trav_info, cell);
      // Consecutive samples mostly stay in one node: skip the index walk then.
      bool same_node = all(equal(trav_coord, cached_coord));
      uint node = same_node ? cached_node : resoct_node_index(trav_depth, trav_coord, trav_log2);
      cached_coord = trav_coord;
      if (node != cached_node) {
        // Alg. 7.5: one descent for all channels in importance order; a channel empty at a
        // node advances the channel index in the same node.
        cached_node = node;
        cached_empty = 0u;
        cached_homog = 0u;
        cached_skip_depth = RESOCT_NONE_U;
        uint ci = 0u;
        uint local = 0u;
        for (uint d = 0u; d <= trav_depth; ++d) {
          ResoctDepthInfo D = resoct_read_depth(d);
          if (d > 0u) {
            local = (local << D.child_shift) |
                    resoct_node_child_bits(D, resoct_ancestor_coord(D, trav_coord, trav_log2));
          }
          if (d < f.start_depth) continue;
          uint nd = D.first_node + local;
          stats.nodes = stats.nodes + 1u;
          while (ci < n) {
            bool empty = ((live >> ci) & 1u) == 0u ||
                         resoct_node_class_carried(nd, d, f.start_depth, trav_coord, trav_log2,
                                                   resoct_read_slot(bank + ci),
                                                   f.node_slot_count) == RESOCT_NODE_CLASS_EMPTY;
            if (!empty) break;
            cached_empty = cached_empty | (1u << ci);
            ci = ci + 1u;
          }
          if (ci == n) {
            cached_skip_depth = d;
            break;
          }
        }
        if (cached_skip_depth == RESOCT_NONE_U) {
          // The remaining channels at the traversal node. A node whose own record is INVALID
          // is requested; its class is carried down from the nearest ancestor with metadata
          // (not empty when there is none).
          bool invalid = false;
          for (uint c = ci; c < n; ++c) {
            if (((live >> c) & 1u) == 0u) {
              cached_empty = cached_empty | (1u << c);
              continue;
            }
            ResoctSlotInfo sc = resoct_read_slot(bank + c);
            uint cls = resoct_node_class(node, sc, f.node_slot_count);
            if (cls == RESOCT_NODE_CLASS_INVALID) {
              invalid = true;
              cls = resoct_node_class_carried(node, trav_depth, f.start_depth, trav_coord,
                                              trav_log2, sc, f.node_slot_count);
              // A homogeneous ancestor's value is only known at the ancestor: read it there.
              if (cls == RESOCT_NODE_CLASS_HOMOGENEOUS) cls = RESOCT_NODE_CLASS_VISIBLE;
            }
            if (cls == RESOCT_NODE_CLASS_EMPTY) cached_empty = cached_empty | (1u << c);
            if (cls == RESOCT_NODE_CLASS_HOMOGENEOUS) cached_homog = cached_homog | (1u << c);
          }
          if (invalid && node != last_node_request) {
            last_node_request = node;
            resoct_report_node_request(node);
            stats.requests = stats.requests + 1u;
          }
          uint all = n >= 32u ? 0xFFFFFFFFu : ((1u << n) - 1u);
          if (cached_empty == all) cached_skip_depth = trav_depth;
        }
      }
      if (cached_skip_depth != RESOCT_NONE_U) {
        ResoctDepthInfo Ds = resoct_read_depth(cached_skip_depth);
        uvec3 nc = resoct_node_coord(Ds, cell);
        uvec3 ne = uvec3(Ds.node_extent_x, Ds.node_extent_y, Ds.node_extent_z);
        skip = true;
        skip_exit = resoct_box_exit(cell, frac, dir_vox, ivec3(nc * ne), vec3(ne));
      } else {
        for (uint c = 0u; c < n; ++c) {
          if (((cached_empty >> c) & 1u) != 0u) continue;
          ResoctSlotInfo s = resoct_read_slot(bank + c);
          float value = 0.0f;
          uint res = RESOCT_CH_NONE;
          if (((cached_homog >> c) & 1u) != 0u) {
            uint mm = resoct_read_node(resoct_node_base(node, s.slot, f.node_slot_count) +
                                       RESOCT_NODE_MINMAX);
            value = float(resoct_node_min16(mm)) / 65535.0f;
            res = RESOCT_CH_VALUE;
          } else {
            uint target = resoct_channel_level(lod, s.finest_level, s.coarsest_level);
            res = resoct_residency_channel(sp, s, node, target, cell, frac, last_key[c], value,
                                           stats);
          }
          if (res == RESOCT_CH_VALUE) {
            vec4 rgba = resoct_tf_lookup(s.slot, value);
            resoct_mix_add(weighted, combined, vec3(rgba.r, rgba.g, rgba.b),
                           resoct_correct_opacity(rgba.a, seg / f.ref_step));
            any_value = true;
          }
        }
      }
    } else {
      // Page-table and standard-octree modes: channels independently; skip only when every
      // live channel is EMPTY, to the nearest EMPTY-brick exit.
      bool all_empty = true;
      for (uint c = 0u; c < n; ++c) {
        if (((live >> c) & 1u) == 0u) continue;
        ResoctSlotInfo s = resoct_read_slot(bank + c);
        uint target = resoct_channel_level(lod, s.finest_level, s.coarsest_level);
        float value = 0.0f;
        float exit_c = 0.0f;
        uint res;
        if (f.mode == RESOCT_MODE_OCTREE) {
          res = resoct_octree_channel(sp, s, target, cell, frac, dir_vox, last_key[c], value,
                                      exit_c, stats);
        } else {
          res = resoct_pagetable_channel(sp, s, target, cell, frac, dir_vox, last_key[c], value,
                                         exit_c, stats);
        }
        if (res == RESOCT_CH_EMPTY) {
          skip_exit = min(skip_exit, exit_c);
        } else {
          all_empty = false;
        }
        if (res == RESOCT_CH_VALUE) {
          vec4 rgba = resoct_tf_lookup(s.slot, value);
          resoct_mix_add(weighted, combined, vec3(rgba.r, rgba.g, rgba.b),
                         resoct_correct_opacity(rgba.a, seg / f.ref_step));
          any_value = true;
        }
      }
      skip = all_empty;
    }

    if (any_value) {
      stats.samples = stats.samples + 1u;
      acc = resoct_composite(acc, resoct_mix_result(weighted, combined));
      if (resoct_saturated(acc, f.ert_opacity)) break;
    }

    if (skip) {
      // First grid segment whose midpoint lies past the exit: sample positions stay those of
      // an unskipped march.
      float k = max(1.0f, ceil((0.5f * seg + skip_exit - 0.5f * dt) / dt));
      float t_next = resoct_advance_t(t, k * dt);
      stats.skipped = stats.skipped + (min(t_next, t_exit) - t);
      t = t_next;
    } else {
      stats.marched = stats.marched + seg;
      t = resoct_advance_t(t, seg);
    }
  }
  return resoct_over_background(acc, background);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_TRAVERSE_GLSL_H
