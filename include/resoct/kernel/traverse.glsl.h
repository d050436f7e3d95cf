// resoct kernel: the per-ray traversal of all three render modes (paper 000 Alg. 1, thesis
// Alg. 7.1-7.5), one source for C++ and GLSL. See docs/rendering.md ("Traversal").
//
// Accessors the including file must define BEFORE including this header (C++: in namespace
// resoct::kernel, after including frame.glsl.h for the record types; GLSL: at global scope,
// typically over storage buffers):
//   uint  resoct_read_node(uint index)               octree word (kernel/octree_node.glsl.h)
//   uint  resoct_read_page(uint index)               page pool word (kernel/page_entry.glsl.h)
//   uint  resoct_read_directory(uint index)          pool block of a directory entry
//   uint  resoct_read_directory_offset(uint table)   first directory entry of (slot, level) table
//   ResoctSlotInfo  resoct_read_slot(uint i)          slot table, importance order
//   ResoctLevelInfo resoct_read_level(uint l)
//   ResoctDepthInfo resoct_read_depth(uint d)
//   float resoct_sample_cache(uint cache_slot, vec3 pos)  raw voxel value, trilinear, pos in
//                                                    padded-brick voxels, centres at i + 0.5
//   void  resoct_report_request(uint device_key)     a missing brick (request_key.glsl.h)
//   void  resoct_report_node_request(uint node)      a node whose metadata is INVALID
//   void  resoct_mark_used(uint cache_slot)          the slot was sampled this frame
//   vec4  resoct_read_tf(uint slot, uint index)      (tf.glsl.h)
//   vec4  resoct_read_preint(uint slot, uint index)  (preintegration.glsl.h)
//   vec4  resoct_read_step_lut(uint index)           (step_lut.glsl.h)
//   uint  resoct_read_visible_subtrees(uint node)    bit i: slot-table entry i finds no unknown
//                                                    node at or below `node`, and too little
//                                                    hidden there to descend for
//                                                    (render/visible_subtrees.hpp); 0 if none
//   float resoct_read_level_size_log2(uint level)    (step.glsl.h)
//   ResoctFxFrame resoct_read_fx_frame()               effect constants (effects.glsl.h)
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
#include "resoct/kernel/effect_sample.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/error_lod.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/node_class.glsl.h"
#include "resoct/kernel/node_run.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/preintegration.glsl.h"
#include "resoct/kernel/projection.glsl.h"
#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/kernel/residency_descent.glsl.h"
#include "resoct/kernel/sample.glsl.h"
#include "resoct/kernel/segment_samples.glsl.h"
#include "resoct/kernel/segments.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/step_lut.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_FN void resoct_stats_clear(RESOCT_OUT(ResoctRayStats) st) {
  st.samples = 0u;
  st.nodes = 0u;
  st.brick_accesses = 0u;
  st.iterations = 0u;
  st.cap_hits = 0u;
  st.requests = 0u;
  st.skipped = 0.0f;
  st.marched = 0.0f;
  st.gradient_evals = 0u;
  st.shadow_rays = 0u;
}

/// Renders one pixel with the effects of RESOCT_EFFECTS (kernel/effects.glsl.h): the
/// premultiplied colour over the background. `stats` receives the ray's counters. With mask 0
/// every effect branch is compiled out.
RESOCT_FX_FN vec4 resoct_render_pixel_fx(RESOCT_FRAME_IN f, uint px, uint py,
                                         RESOCT_OUT(ResoctRayStats) stats) {
  resoct_stats_clear(stats);
  // The render mode: a constant in the CPU backend's per-mode specializations (effects.glsl.h).
  uint mode = RESOCT_FX_MODE(f);
  vec4 background = vec4(f.background_r, f.background_g, f.background_b, f.background_a);
  vec4 acc = vec4(0.0f);

  // Channels whose transfer function is invisible everywhere never contribute: drop them in
  // every mode (no samples, no requests).
  uint n = RESOCT_FX_SLOT_COUNT(f);
  uint live = 0u;
  for (uint i = 0u; i < n; ++i) {
    if (resoct_read_slot(i).vis_bins != 0u) live = live | (1u << i);
  }
  if (live == 0u && f.slice_count == 0u) return resoct_over_background(acc, background);
  // A lens changes `live` per segment; projections report every channel live anywhere.
  uint live_anywhere = live;

  vec3 dir_box;
  ivec3 o_cell;
  vec3 o_frac;
  resoct_camera_ray(f, px, py, dir_box, o_cell, o_frac);
  vec3 dir_vox = dir_box * resoct_frame_voxels_per_box(f);
  // Every ray/box test of the march multiplies by these (kernel/ray.glsl.h).
  vec3 inv_vox = resoct_ray_inverse(dir_vox);

  // Volume interval relative to the origin cell: exact integer box corners.
  vec3 vol_lo = vec3(-o_cell);
  vec3 vol_hi = vec3(ivec3(int(f.extent_x), int(f.extent_y), int(f.extent_z)) - o_cell);
  vec2 tv = resoct_ray_box_inv(o_frac, inv_vox, vol_lo, vol_hi);
  float t = max(tv.x, 0.0f);
  float t_exit = tv.y;
  if (!(t < t_exit)) return resoct_over_background(acc, background);

  vec3 finest = vec3(f.finest_voxel_x, f.finest_voxel_y, f.finest_voxel_z);
  float dt = resoct_step_size(dir_box, finest, f.step_scale, f.min_step);
  // The full step rounded down to its step level, whose LUT holds the corrected, premultiplied
  // colours of full steps (kernel/step_lut.glsl.h); without one, every sample corrects itself.
  uint step_level = resoct_step_level(f, resoct_step_ratio(dt, f.ref_step));
  if (step_level != RESOCT_STEP_LEVEL_NONE)
    dt = resoct_step_level_ratio(f, step_level) * f.ref_step;
  uint trav_depth = resoct_traversal_depth(f, dt);
  ResoctSampleParams sp = resoct_sample_params(f);

  uint last_key[RESOCT_MAX_SLOTS];
  for (uint i = 0u; i < RESOCT_MAX_SLOTS; ++i) last_key[i] = RESOCT_REQUEST_KEY_NONE;
  uint last_node_request = RESOCT_NONE_U;

  // Residency mode: the last traversal node and the path to it (kernel/residency_descent.glsl.h).
  ResoctDescent ds;
  ResoctDescentPath dp;
  resoct_descent_clear(ds, dp);
  // The traversal depth capped for the LOD level cap_lod (RESOCT_NONE_U: not computed yet).
  uint cap_lod = RESOCT_NONE_U;
  uint cap_depth = trav_depth;
  // The least resoct_brick_depth_end of the live channels' levels at cap_lod: a node shallower
  // than this contains every channel's target brick at any position inside it.
  uint brick_depth_end = 0u;

  // Effects: per-ray state and constants (only touched by specializations that use them).
  ResoctFxRay fx;
  ResoctFxRayConst rc;
  ResoctFxParams fxp;
  RESOCT_IF_FX(RESOCT_EFFECT_ANY) {
    resoct_fx_ray_clear(fx);
    rc.o_cell = o_cell;
    rc.o_frac = o_frac;
    rc.dir_box = dir_box;
    rc.dir_vox = dir_vox;
    rc.n = n;
    rc.live = live;
    fxp = resoct_fx_params(f, resoct_read_fx_frame());
  }
  // Pre-integration: each channel's previous value (kernel/preintegration.glsl.h).
  ResoctPreintRay pr;
  RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
    resoct_preint_ray_clear(pr);
  }
  float t_enter = t;
  // Jittered accumulation: every sample moves by jitter_sample steps (t + 0 * dt == t).
  t = t + f.jitter_sample * dt;
  // The step grid: step j starts at t_grid + j * dt (resoct_grid_t), so skipping changes which
  // samples run but never where they are, to the bit. Restarted at each slice or lens stop.
  float t_grid = t;
  uint grid_j = 0u;
  float inv_dt = 1.0f / dt;  // skips count steps with a product (same float on every backend)

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
  // One pass of the outer loop per segment (a single pass without slices and lens). The segment
  // switch stays out of the march loop's condition: there it made lavapipe's compiler take
  // extra loop back-edges per step, which count against the driver's per-invocation loop guard
  // (docs/vulkan-backend.md) and cut long rays short.
  bool stop = false;
  // The current ray segment (docs/rendering.md "Segments"): until seg_next, every channel's
  // lookup (classification, level, page entry, substitution, requests, used slot) is that of the
  // segment's first sample, kept in src[]: the samples in between only sample, look up the
  // transfer function and composite.
  bool have_seg = false;    // src[] holds sources (they may still need a new decision)
  float lod_t_end = 0.0f;   // where the LOD level may change
  float seg_t_end = 0.0f;   // where the sources stop holding (their boxes, the LOD level)
  float node_t_end = 0.0f;  // where the residency node's classes stop holding
  float seg_next = 0.0f;    // min(seg_t_end, node_t_end): the next decision
  uint seg_lod = 0u;
  uint seg_node = 0u;           // node the sources were decided in
  uint seg_empty = 0u;          // channels the node's classes settled then: empty,
  uint seg_homog = 0u;          //   homogeneous
  bool seg_node_dep = false;    // some source depends on that node
  uint seg_values = 0u;         // channels whose sources yield values (RESOCT_CH_VALUE)
  ivec3 seg_box_lo = ivec3(0);  // the level-0 box in which the sources hold
  ivec3 seg_box_hi = ivec3(0);
  ResoctSource src[RESOCT_MAX_SLOTS];
  // Residency mode: half a voxel of the coarsest level a live channel samples, per axis (0 at
  // level 0): node metadata covers the node dilated by one level-0 voxel, which covers the
  // trilinear support of a level-l sample only this far inside the node (docs/rendering.md
  // "Exact culling").
  ivec3 margin = ivec3(0);
  // Error-bounded LOD (error_lod.glsl.h): whether a live channel uses it; their levels, and so
  // the margin, are then known only per decision.
  bool eb_live = false;
  for (;;) {
    while (t_exit - t > RESOCT_SEGMENT_EPS * dt) {
      if (stats.iterations >= f.max_iterations) {
        stats.cap_hits = 1u;
        stop = true;
        break;
      }
      stats.iterations = stats.iterations + 1u;
      float seg = resoct_segment_length(t, dt, t_exit);
      float tm = t + 0.5f * seg;
      // The exact position (integer cell + fraction) is needed only where decisions are made:
      // at a segment's first sample, and by effects.
      ivec3 cell = ivec3(0);
      vec3 frac = vec3(0.0f);

      bool skip = false;
      float skip_exit = RESOCT_RAY_T_INF;
      if (!have_seg || !(tm < seg_next)) {
        // ---- A decision: the node's class (residency) and, where they may have changed, the
        // channels' sources, all at this sample. ----
        resoct_ray_position(o_cell, o_frac, dir_vox, tm, cell, frac);
        resoct_clamp_position(f, cell, frac);
        bool new_sources = !have_seg || !(tm < seg_t_end);
        // The LOD level is chosen anew (per-sample rule) only past the point where it may change.
        if (!(tm < lod_t_end)) {
          float budget = resoct_lod_budget_log2(f.footprint_base, f.footprint_slope,
                                                resoct_view_depth(f, dir_box, tm), f.lod_error_px);
          seg_lod = resoct_lod_level(budget, f.level_count);
          lod_t_end = resoct_lod_change_t(f.footprint_base, f.footprint_slope,
                                          resoct_view_depth(f, dir_box, 1.0f), f.lod_error_px,
                                          seg_lod, f.level_count);
          new_sources = true;
        }
        uint lod = seg_lod;
        node_t_end = RESOCT_RAY_T_INF;
        // Residency mode: where the node's classes hold, and which channels they settle.
        ivec3 class_lo = ivec3(0);
        ivec3 class_hi = ivec3(0);
        uint class_empty = 0u;
        uint class_homog = 0u;
        uint node = 0u;
        if (mode == RESOCT_MODE_RESIDENCY) {
          // This sample's traversal depth: the ray's, capped at nodes of two voxels (a trilinear
          // footprint) of the finest level a live channel samples here (ResoctLevelInfo.depth_cap).
          // The LOD level changes rarely along a ray; a new slice/lens segment (ds.node
          // reset) may change the bank and with it the channels' level ranges.
          if (lod != cap_lod || ds.node == RESOCT_NONE_U) {
            cap_lod = lod;
            uint cap_level = RESOCT_NONE_U;
            uvec3 coarse_f = uvec3(0u);
            eb_live = false;
            brick_depth_end = RESOCT_NONE_U;
            for (uint c = 0u; c < n; ++c) {
              if (((live >> c) & 1u) == 0u) continue;
              RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(bank + c);
              uint lc = resoct_channel_level(lod, s.finest_level, s.coarsest_level);
              // Error-bounded LOD may sample any of the channel's levels (error_lod.glsl.h).
              cap_level = min(cap_level, RESOCT_FX(resoct_error_bounded_finest)(s, lc));
              uint lm = RESOCT_FX(resoct_error_bounded_coarsest)(s, lc);
              RESOCT_IN(ResoctLevelInfo) Lc = resoct_read_level(lm);
              coarse_f = max(coarse_f, resoct_level_factor(Lc));
              eb_live = eb_live || RESOCT_FX(resoct_error_bounded_on)(s);
              brick_depth_end =
                  min(brick_depth_end, resoct_brick_depth_end(f, Lc, resoct_frame_brick_size(sp)));
            }
            if (cap_level == RESOCT_NONE_U) {
              cap_level = lod;
              brick_depth_end = 0u;
            }
            cap_depth = min(trav_depth, resoct_read_level(cap_level).depth_cap);
            margin = resoct_culling_margin(coarse_f);
          }
          // The traversal node of this sample (kernel/residency_descent.glsl.h).
          if (!resoct_descent_holds(ds, cap_depth, cell)) {
            RESOCT_FX(resoct_residency_descend)
            (f, bank, n, live, cap_depth, cell, fx, ds, dp, last_node_request, stats);
          }
          node = ds.node;
          // A node's class holds in the node shrunk by the margin (the whole node at level 0);
          // in the rest of it (the rim) every live channel is looked up, and entering the shrunk
          // part is a new decision.
          uint live_mask = live & (n >= 32u ? 0xFFFFFFFFu : ((1u << n) - 1u));
          // With error-bounded LOD the margin follows the levels chosen here, and the classes
          // hold only where those choices do ([eb_lo, eb_hi)).
          ivec3 dmargin = margin;
          ivec3 eb_lo = ivec3(-2147483647);
          ivec3 eb_hi = ivec3(2147483647);
          if (eb_live) {
            dmargin = resoct_culling_margin(
                RESOCT_FX(resoct_error_bounded_factor)(sp, bank, n, live, lod, cell, eb_lo, eb_hi));
          }
          if (ds.skip_depth != RESOCT_NONE_U) {
            RESOCT_IN(ResoctDepthInfo) Ds = resoct_read_depth(ds.skip_depth);
            ivec3 ne = ivec3(Ds.node_extent_x, Ds.node_extent_y, Ds.node_extent_z);
            class_lo = ivec3(resoct_node_coord(Ds, cell)) * ne;
            class_hi = class_lo + ne;
            ivec3 ilo = class_lo + dmargin;
            ivec3 ihi = class_hi - dmargin;
            if (eb_live) {
              ilo = max(ilo, eb_lo);
              ihi = min(ihi, eb_hi);
            }
            if (resoct_in_box(cell, ilo, ihi)) {
              skip = true;
              skip_exit = resoct_box_exit_t(cell, frac, inv_vox, ilo, ihi);
              // At level 0 (no margin) the skip goes on through the empty nodes that follow.
              bool run = all(equal(dmargin, ivec3(0)));
              RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
                run = false;
              }
              if (run) {
                skip_exit =
                    resoct_node_run_end(f, bank, n, live, RESOCT_NODE_CLASS_EMPTY, ds.skip_depth,
                                        ds.node, resoct_node_coord(Ds, cell), class_lo, cell, frac,
                                        dir_vox, inv_vox, skip_exit, eb_lo, eb_hi, stats);
              }
            } else {
              node_t_end = min(resoct_box_exit_t(cell, frac, inv_vox, class_lo, class_hi),
                               resoct_box_entry_t(cell, frac, inv_vox, ilo, ihi));
            }
          } else {
            class_lo = ds.lo;
            class_hi = ds.hi;
            class_empty = ds.empty & live_mask;
            class_homog = ds.homog & live_mask & ~class_empty;
            // A node (the traversal node or a visible ancestor) that settles no channel and
            // contains every live channel's target brick: each source box lies inside it (a
            // substitute's is clipped to it), so the node ends no earlier than the sources and
            // its exit cannot be the next decision; node_t_end stays infinite.
            bool holds_sources =
                (class_empty | class_homog) == 0u && min(ds.full_depth, ds.depth) < brick_depth_end;
            if (!holds_sources) {
              ivec3 ilo = class_lo;
              ivec3 ihi = class_hi;
              if ((class_empty | class_homog) != 0u && any(greaterThan(dmargin, ivec3(0)))) {
                ilo = ilo + dmargin;
                ihi = ihi - dmargin;
              }
              if ((class_empty | class_homog) != 0u && eb_live) {
                ilo = max(ilo, eb_lo);
                ihi = min(ihi, eb_hi);
              }
              if (resoct_in_box(cell, ilo, ihi)) {
                node_t_end = resoct_box_exit_t(cell, frac, inv_vox, ilo, ihi);
              } else {
                class_empty = 0u;
                class_homog = 0u;
                node_t_end = min(resoct_box_exit_t(cell, frac, inv_vox, class_lo, class_hi),
                                 resoct_box_entry_t(cell, frac, inv_vox, ilo, ihi));
              }
            }
          }
          // Sources stay while they hold (their bricks, the LOD level) unless the classes
          // settle other channels, or a source depends on the node (a substitute chosen by its
          // residency word, a homogeneous node's value) and the node changed.
          if (!skip && !new_sources &&
              (class_empty != seg_empty || class_homog != seg_homog ||
               (seg_node_dep && node != seg_node))) {
            new_sources = true;
          }
        }
        if (skip) {
          // After the skip the class is decided anew; sources that still hold are kept.
          node_t_end = 0.0f;
        } else if (new_sources) {
          ivec3 src_lo = ivec3(-2147483647);
          ivec3 src_hi = ivec3(2147483647);
          seg_node = node;
          seg_empty = class_empty;
          seg_homog = class_homog;
          seg_node_dep = false;
          if (mode == RESOCT_MODE_RESIDENCY) {
            // Channels the node does not settle may still be settled by their bricks: an EMPTY
            // brick (page state) is transparent over its box, as in page-table mode. When every
            // channel is settled one way or the other, the march skips to the first place where
            // one of them stops holding, instead of stepping through samples that add nothing.
            bool all_empty = (live & ~class_empty) != 0u;
            RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
              all_empty = false;
            }
            for (uint c = 0u; c < n; ++c) {
              src[c] = resoct_source_of(RESOCT_CH_NONE, 0.0f);
              if ((((live & ~class_empty) >> c) & 1u) == 0u) continue;
              RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(bank + c);
              if (((class_homog >> c) & 1u) != 0u) {
                // Homogeneous here: the node's value, no brick.
                uint mm = resoct_read_node(resoct_node_base(node, s.slot, f.node_slot_count) +
                                           RESOCT_NODE_MINMAX);
                src[c] = resoct_source_value(s, float(resoct_node_min16(mm)) / 65535.0f);
                seg_node_dep = true;
              } else {
                uint target = RESOCT_FX(resoct_error_bounded_level)(
                    sp, s, resoct_channel_level(lod, s.finest_level, s.coarsest_level), cell);
                uint requests_before = stats.requests;
                src[c] = resoct_residency_source(sp, s, node, class_lo, class_hi, target, cell,
                                                 last_key[c], src_lo, src_hi, stats);
                // A missing target (requested, perhaps substituted) depends on the node.
                if (src[c].level != target || src[c].kind == RESOCT_CH_NONE ||
                    stats.requests != requests_before) {
                  seg_node_dep = true;
                }
              }
              if (src[c].kind != RESOCT_CH_EMPTY) all_empty = false;
            }
            if (all_empty) {
              // The node's classes hold until node_t_end, the bricks over [src_lo, src_hi), the
              // bricks' level until lod_t_end (a finer level's bricks need not be empty).
              skip = true;
              skip_exit = min(min(node_t_end, lod_t_end - tm),
                              resoct_box_exit_t(cell, frac, inv_vox, src_lo, src_hi));
            }
          } else {
            // Page-table and standard-octree modes: channels independently; skip only when every
            // live channel is EMPTY, to the nearest EMPTY-brick exit.
            bool all_empty = true;
            for (uint c = 0u; c < n; ++c) {
              src[c] = resoct_source_of(RESOCT_CH_NONE, 0.0f);
              if (((live >> c) & 1u) == 0u) continue;
              RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(bank + c);
              uint target = RESOCT_FX(resoct_error_bounded_level)(
                  sp, s, resoct_channel_level(lod, s.finest_level, s.coarsest_level), cell);
              float exit_c = 0.0f;
              if (mode == RESOCT_MODE_OCTREE) {
                src[c] = resoct_octree_source(sp, s, target, f.start_depth, cell, frac, inv_vox,
                                              last_key[c], last_node_request, src_lo, src_hi,
                                              exit_c, stats);
              } else {
                src[c] = resoct_pagetable_source(sp, s, target, cell, frac, inv_vox, last_key[c],
                                                 src_lo, src_hi, exit_c, stats);
              }
              if (src[c].kind == RESOCT_CH_EMPTY) {
                skip_exit = min(skip_exit, exit_c);
              } else {
                all_empty = false;
              }
            }
            skip = all_empty;
          }
          if (skip) {
            have_seg = false;
          } else {
            // The sources hold until the ray leaves their boxes or the LOD level may change
            // (docs/rendering.md "Segments").
            seg_t_end = min(lod_t_end, tm + resoct_box_exit_t(cell, frac, inv_vox, src_lo, src_hi));
            seg_box_lo = src_lo;
            seg_box_hi = src_hi;
            have_seg = true;
            seg_values = 0u;
            for (uint c = 0u; c < n; ++c) {
              resoct_source_along_ray(src[c], o_cell, o_frac, dir_vox, sp.halo);
              if (src[c].kind == RESOCT_CH_VALUE) seg_values = seg_values | (1u << c);
            }
          }
        }
        // Consecutive nodes in which every live channel is visible form one segment: the
        // nodes the ray enters next inside the sources' box are classified here, so that
        // crossing into them is no decision (docs/rendering.md "Segments"). Only where nothing
        // at the node settles a channel (no empty or homogeneous class, no source chosen by the
        // node), and not for projections, whose classes follow the values along the ray.
        bool merge = mode == RESOCT_MODE_RESIDENCY && !skip && ds.skip_depth == RESOCT_NONE_U &&
                     ds.full_depth == RESOCT_NONE_U && class_empty == 0u && class_homog == 0u &&
                     !seg_node_dep;
        // A run can only move the next decision when the node ends before the sources do: a
        // longer node_t_end leaves min(seg_t_end, node_t_end) at seg_t_end (t + x is monotonic).
        if (merge && !(tm + node_t_end < seg_t_end)) merge = false;
        RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
          merge = false;
        }
        if (merge) {
          node_t_end = resoct_node_run_end(f, bank, n, live, RESOCT_NODE_CLASS_VISIBLE, cap_depth,
                                           ds.node, ds.coord, class_lo, cell, frac, dir_vox,
                                           inv_vox, node_t_end, seg_box_lo, seg_box_hi, stats);
        }
        if (!skip) node_t_end = tm + node_t_end;
        seg_next = min(seg_t_end, node_t_end);
      }

      // Without effects, the samples of a segment whose only values come from one channel run
      // in a loop of their own (kernel/segment_samples.glsl.h); else one sample per pass. The
      // loop is entered even for one sample: the same arithmetic, and cheaper than a pass of the
      // march (measured with callgrind on the sphere: a floor of two steps cost more).
      bool single = false;
      RESOCT_IF_FX(RESOCT_EFFECT_ANY | RESOCT_EFFECT_PREINT) {}
      else {
        single =
            !skip && seg_values != 0u && (seg_values & (seg_values - 1u)) == 0u && tm < seg_next;
      }
      if (single) {
        stop = RESOCT_SEGMENT_SAMPLES(f, src[findLSB(seg_values)], dt, step_level, t_exit, seg_next,
                                      seg, tm, t_grid, grid_j, t, acc, stats);
        if (stop) break;
        continue;
      }
#ifdef RESOCT_SEGMENT_SAMPLES_MULTI
      // A backend's loop for segments in which several channels yield values, with the
      // arithmetic of the pass below (the CPU backend's packets; GLSL runs the pass).
      bool multi = false;
      RESOCT_IF_FX(RESOCT_EFFECT_ANY | RESOCT_EFFECT_PREINT) {}
      else {
        multi = !skip && (seg_values & (seg_values - 1u)) != 0u && tm < seg_next;
      }
      if (multi) {
        stop = RESOCT_SEGMENT_SAMPLES_MULTI(f, src, seg_values, n, dt, step_level, t_exit, seg_next,
                                            seg, tm, t_grid, grid_j, t, acc, stats);
        if (stop) break;
        continue;
      }
#endif

      bool any_value = false;
      vec4 weighted;
      float combined;
      resoct_mix_begin(weighted, combined);
      if (!skip) {
        RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
          acc = resoct_preint_begin_sample(pr, seg_lod, resoct_step_ratio(seg, f.ref_step), acc);
        }
        // Effects: the channels' values are collected and handled by one call below, so the GPU
        // compiler inlines the effect code once, not once per render mode.
        float fx_value[RESOCT_MAX_SLOTS];
        uint fx_level[RESOCT_MAX_SLOTS];
        uint fx_have = 0u;
        RESOCT_IF_FX(RESOCT_EFFECT_ANY) {
          resoct_ray_position(o_cell, o_frac, dir_vox, tm, cell, frac);
          resoct_clamp_position(f, cell, frac);
        }
        for (uint c = 0u; c < n; ++c) {
          if (src[c].kind != RESOCT_CH_VALUE) continue;
          float value;
          resoct_source_sample_t(src[c], tm, value, stats);
          RESOCT_IF_FX(RESOCT_EFFECT_ANY) {
            RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(bank + c);
            uint level = resoct_channel_level(seg_lod, s.finest_level, s.coarsest_level);
            RESOCT_IF_FX(RESOCT_EFFECT_SHADING | RESOCT_EFFECT_ISO) {
              if (mode == RESOCT_MODE_RESIDENCY) {
                level = resoct_present_level(sp, s, seg_node, level, cell);
              } else if (mode == RESOCT_MODE_OCTREE) {
                level = resoct_octree_level(sp, s, level, cell);
              }
            }
            fx_value[c] = value;
            fx_level[c] = level;
            fx_have = fx_have | (1u << c);
          }
          else {
            // Full steps of a ray with a step level: the level's corrected, premultiplied LUT
            // (not with pre-integration, whose tables integrate between two values).
            bool from_level = seg == dt && step_level != RESOCT_STEP_LEVEL_NONE;
            RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
              from_level = false;
            }
            if (from_level) {
              resoct_mix_add_premultiplied(
                  weighted, combined,
                  resoct_step_lut_lookup(src[c].tf_slot, step_level, f.step_level_count, value));
            } else {
              vec4 rgba = RESOCT_FX(resoct_dvr_sample)(pr, c, src[c].tf_slot, value,
                                                       resoct_step_ratio(seg, f.ref_step));
              resoct_mix_add(weighted, combined, vec3(rgba.r, rgba.g, rgba.b), rgba.a);
            }
          }
          any_value = true;
        }

        RESOCT_IF_FX(RESOCT_EFFECT_ANY) {
          for (uint c = 0u; c < n; ++c) {
            if (((fx_have >> c) & 1u) == 0u) continue;
            RESOCT_FX(resoct_fx_channel)
            (sp, fxp, rc, c, resoct_read_slot(bank + c), src[c], fx_value[c], fx_level[c], seg_lod,
             seg, tm, cell, frac, fx, pr, weighted, combined, acc, stats);
          }
        }
        RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
          acc = resoct_preint_end_sample(pr, acc);
        }
      } else {
        RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
          acc = resoct_preint_begin_sample(pr, seg_lod, resoct_step_ratio(seg, f.ref_step), acc);
          acc = resoct_preint_end_sample(pr, acc);
        }
      }

      if (any_value) {
        stats.samples = stats.samples + 1u;
        acc = resoct_composite(acc, resoct_mix_result(weighted, combined));
        if (resoct_saturated(acc, f.ert_opacity)) {
          stop = true;
          break;
        }
      }

      if (skip) {
        // First grid segment whose midpoint lies past the exit: sample positions stay those of
        // an unskipped march.
        float k = max(1.0f, resoct_ceil((0.5f * seg + skip_exit - 0.5f * dt) * inv_dt));
        float t_next;
        if (k < 16777216.0f) {
          grid_j = grid_j + uint(k);
          t_next = resoct_grid_t(t_grid, grid_j, dt, t);
        } else {
          // Past any ray's end (an exit at infinity): no grid index needed.
          t_next = resoct_advance_t(t, k * dt);
        }
        stats.skipped = stats.skipped + (min(t_next, t_exit) - t);
        t = t_next;
      } else {
        stats.marched = stats.marched + seg;
        grid_j = grid_j + 1u;
        t = resoct_grid_t(t_grid, grid_j, dt, t);
      }
    }
    RESOCT_IF_FX(RESOCT_EFFECT_PREINT) {
      if (!stop) acc = resoct_preint_flush(pr, acc);
    }
    if (stop || segs.enabled == 0u ||
        !resoct_segment_advance(f, segs, o_cell, o_frac, dir_box, dir_vox, dt, t, t_exit, acc, live,
                                bank, ds.node, ds.coord, stats)) {
      break;
    }
    have_seg = false;
    t_grid = t;
    grid_j = 0u;
  }
  RESOCT_IF_FX(RESOCT_EFFECT_PROJECTION) {
    acc = resoct_fx_projection_composite(fx, n, live_anywhere, t_exit - t_enter, acc);
  }
  return resoct_over_background(acc, background);
}

/// Renders one pixel without effects (C++), or with the pipeline's RESOCT_EFFECTS (GLSL).
RESOCT_FN vec4 resoct_render_pixel(RESOCT_FRAME_IN f, uint px, uint py,
                                   RESOCT_OUT(ResoctRayStats) stats) {
  return RESOCT_FX_PLAIN(resoct_render_pixel_fx)(f, px, py, stats);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_TRAVERSE_GLSL_H
