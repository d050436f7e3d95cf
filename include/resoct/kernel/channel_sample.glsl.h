// resoct kernel: what one channel yields at one sample in each render mode (residency with
// substitution, page table, standard octree), plus the request strategy. Used by
// traverse.glsl.h; see docs/rendering.md ("Traversal").
//
// Accessors: as listed in traverse.glsl.h (pages, levels, nodes, cache, requests, used slots).
#ifndef RESOCT_KERNEL_CHANNEL_SAMPLE_GLSL_H
#define RESOCT_KERNEL_CHANNEL_SAMPLE_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/kernel/sample.glsl.h"
#include "resoct/kernel/tf.glsl.h"

RESOCT_KERNEL_BEGIN

// What one channel yields at one sample.
RESOCT_CONST(uint, RESOCT_CH_NONE, 0u);   // no data (missing, culled): contributes nothing
RESOCT_CONST(uint, RESOCT_CH_VALUE, 1u);  // a normalized value
RESOCT_CONST(uint, RESOCT_CH_EMPTY, 2u);  // provably transparent (EMPTY brick): may be skipped

/// The few frame constants the per-channel helpers need (passing the whole ResoctFrame by value
/// would copy ~220 bytes per call on the CPU where the compiler does not inline).
struct ResoctSampleParams {
  uint level_count;
  uint node_slot_count;
  uint halo;
  uint request_greedy;
  uint brick_x;
  uint brick_y;
  uint brick_z;
};

RESOCT_FN ResoctSampleParams resoct_sample_params(ResoctFrame f) {
  ResoctSampleParams p;
  p.level_count = f.level_count;
  p.node_slot_count = f.node_slot_count;
  p.halo = f.halo;
  p.request_greedy = f.request_greedy;
  p.brick_x = f.brick_x;
  p.brick_y = f.brick_y;
  p.brick_z = f.brick_z;
  return p;
}

RESOCT_FN uvec3 resoct_frame_brick_size(ResoctSampleParams f) {
  return uvec3(f.brick_x, f.brick_y, f.brick_z);
}

/// Levels a slot may use as a bitmask: [finest, coarsest].
RESOCT_FN uint resoct_allowed_levels(ResoctSlotInfo s) {
  uint hi = s.coarsest_level >= 31u ? 0xFFFFFFFFu : ((2u << s.coarsest_level) - 1u);
  return hi & ~((1u << s.finest_level) - 1u);
}

/// Parameter offset (from the position) at which the ray leaves the integer box [lo, lo + size),
/// computed in box-local coordinates so that huge axes neither stall nor overshoot.
RESOCT_FN float resoct_box_exit(ivec3 cell, vec3 frac, vec3 dir_vox, ivec3 lo, vec3 size) {
  return resoct_ray_node_local(resoct_relative_origin(cell, frac, lo), dir_vox, size).y;
}

/// The value of a present (not UNMAPPED) page entry.
RESOCT_FN uint resoct_entry_value(ResoctSlotInfo s, uint entry, ResoctLevelInfo L, uvec3 brick_size,
                                  uint halo, uvec3 brick, ivec3 cell, vec3 frac,
                                  RESOCT_OUT(float) value, RESOCT_INOUT(ResoctRayStats) st) {
  value = 0.0f;
  uint state = resoct_page_state(entry);
  if (state == RESOCT_PAGE_STATE_EMPTY) return RESOCT_CH_EMPTY;
  if (state == RESOCT_PAGE_STATE_HOMOGENEOUS) {
    value = resoct_page_homogeneous_value(entry);
    return RESOCT_CH_VALUE;
  }
  if (state != RESOCT_PAGE_STATE_MAPPED) return RESOCT_CH_NONE;
  st.brick_accesses = st.brick_accesses + 1u;
  float raw = resoct_sample_mapped(entry, L, brick_size, halo, brick, cell, frac);
  value = resoct_normalize_value(raw, s.range_lo, s.inv_range_width);
  return RESOCT_CH_VALUE;
}

/// Requests the target brick of a missing sample (once per ray and slot while the key repeats)
/// and, greedy, every coarser level's brick at the position up to the first present one.
RESOCT_FN void resoct_request_missing(ResoctSampleParams f, ResoctSlotInfo s, uint level,
                                      ivec3 cell, RESOCT_INOUT(uint) last_key,
                                      RESOCT_INOUT(ResoctRayStats) st) {
  uvec3 bs = resoct_frame_brick_size(f);
  ResoctLevelInfo L = resoct_read_level(level);
  uint key =
      resoct_brick_request_key(s.slot, level, f.level_count, L, resoct_brick_at(L, bs, cell));
  if (key == last_key) return;
  last_key = key;
  resoct_report_request(key);
  st.requests = st.requests + 1u;
  if (f.request_greedy == 0u) return;
  for (uint l = level + 1u; l <= s.coarsest_level; ++l) {
    ResoctLevelInfo Lc = resoct_read_level(l);
    uvec3 b = resoct_brick_at(Lc, bs, cell);
    if (resoct_page_state(resoct_page_entry_of(s.slot, l, f.level_count, Lc, b)) !=
        RESOCT_PAGE_STATE_UNMAPPED) {
      break;
    }
    resoct_report_request(resoct_brick_request_key(s.slot, l, f.level_count, Lc, b));
    st.requests = st.requests + 1u;
  }
}

/// Residency mode, one non-empty channel at the traversal node: the target level if present,
/// else request it and substitute the nearest partially resident level, coarser first, then
/// finer, checking the actual page entry at the position for each candidate.
RESOCT_FN uint resoct_residency_channel(ResoctSampleParams f, ResoctSlotInfo s, uint node,
                                        uint target, ivec3 cell, vec3 frac,
                                        RESOCT_INOUT(uint) last_key, RESOCT_OUT(float) value,
                                        RESOCT_INOUT(ResoctRayStats) st) {
  value = 0.0f;
  uvec3 bs = resoct_frame_brick_size(f);
  ResoctLevelInfo L = resoct_read_level(target);
  uvec3 b = resoct_brick_at(L, bs, cell);
  uint e = resoct_page_entry_of(s.slot, target, f.level_count, L, b);
  if (resoct_page_state(e) != RESOCT_PAGE_STATE_UNMAPPED) {
    return resoct_entry_value(s, e, L, bs, f.halo, b, cell, frac, value, st);
  }
  resoct_request_missing(f, s, target, cell, last_key, st);
  uint r =
      resoct_read_node(resoct_node_base(node, s.slot, f.node_slot_count) + RESOCT_NODE_RESIDENCY) &
      resoct_allowed_levels(s);
  if (r == 0u) return RESOCT_CH_NONE;
  int l = resoct_node_next_coarser(r, target);
  while (l >= 0) {
    uint lu = uint(l);
    ResoctLevelInfo Lc = resoct_read_level(lu);
    uvec3 bc = resoct_brick_at(Lc, bs, cell);
    uint ec = resoct_page_entry_of(s.slot, lu, f.level_count, Lc, bc);
    if (resoct_page_state(ec) != RESOCT_PAGE_STATE_UNMAPPED) {
      return resoct_entry_value(s, ec, Lc, bs, f.halo, bc, cell, frac, value, st);
    }
    l = resoct_node_next_coarser(r, lu);
  }
  l = resoct_node_next_finer(r, target);
  while (l >= 0) {
    uint lu = uint(l);
    ResoctLevelInfo Lf = resoct_read_level(lu);
    uvec3 bf = resoct_brick_at(Lf, bs, cell);
    uint ef = resoct_page_entry_of(s.slot, lu, f.level_count, Lf, bf);
    if (resoct_page_state(ef) != RESOCT_PAGE_STATE_UNMAPPED) {
      return resoct_entry_value(s, ef, Lf, bs, f.halo, bf, cell, frac, value, st);
    }
    l = resoct_node_next_finer(r, lu);
  }
  return RESOCT_CH_NONE;
}

/// Page-table mode, one channel: the target level or nothing (requested). `skip_exit` receives
/// the exit offset of an EMPTY brick.
RESOCT_FN uint resoct_pagetable_channel(ResoctSampleParams f, ResoctSlotInfo s, uint target,
                                        ivec3 cell, vec3 frac, vec3 dir_vox,
                                        RESOCT_INOUT(uint) last_key, RESOCT_OUT(float) value,
                                        RESOCT_OUT(float) skip_exit,
                                        RESOCT_INOUT(ResoctRayStats) st) {
  skip_exit = 0.0f;
  uvec3 bs = resoct_frame_brick_size(f);
  ResoctLevelInfo L = resoct_read_level(target);
  uvec3 b = resoct_brick_at(L, bs, cell);
  uint e = resoct_page_entry_of(s.slot, target, f.level_count, L, b);
  if (resoct_page_state(e) == RESOCT_PAGE_STATE_UNMAPPED) {
    value = 0.0f;
    resoct_request_missing(f, s, target, cell, last_key, st);
    return RESOCT_CH_NONE;
  }
  uint res = resoct_entry_value(s, e, L, bs, f.halo, b, cell, frac, value, st);
  if (res == RESOCT_CH_EMPTY) {
    skip_exit =
        resoct_box_exit(cell, frac, dir_vox, resoct_brick_lo0(L, bs, b), resoct_brick_size0(L, bs));
  }
  return res;
}

/// Standard-octree mode, one channel: walk the levels from the slot's coarsest to the target at
/// the position (one node per level); the first missing level is requested and ends the walk,
/// the finest present level above it is sampled; an EMPTY level makes the channel empty there.
RESOCT_FN uint resoct_octree_channel(ResoctSampleParams f, ResoctSlotInfo s, uint target,
                                     ivec3 cell, vec3 frac, vec3 dir_vox,
                                     RESOCT_INOUT(uint) last_key, RESOCT_OUT(float) value,
                                     RESOCT_OUT(float) skip_exit, RESOCT_INOUT(ResoctRayStats) st) {
  value = 0.0f;
  skip_exit = 0.0f;
  uvec3 bs = resoct_frame_brick_size(f);
  uint best_entry = RESOCT_PAGE_UNMAPPED_WORD;
  uint best_level = 0u;
  uvec3 best_brick = uvec3(0u);
  uint l = s.coarsest_level + 1u;
  while (l > target) {
    l = l - 1u;
    st.nodes = st.nodes + 1u;
    ResoctLevelInfo L = resoct_read_level(l);
    uvec3 b = resoct_brick_at(L, bs, cell);
    uint e = resoct_page_entry_of(s.slot, l, f.level_count, L, b);
    uint state = resoct_page_state(e);
    if (state == RESOCT_PAGE_STATE_UNMAPPED) {
      resoct_request_missing(f, s, l, cell, last_key, st);
      break;
    }
    if (state == RESOCT_PAGE_STATE_EMPTY) {
      skip_exit = resoct_box_exit(cell, frac, dir_vox, resoct_brick_lo0(L, bs, b),
                                  resoct_brick_size0(L, bs));
      return RESOCT_CH_EMPTY;
    }
    best_entry = e;
    best_level = l;
    best_brick = b;
  }
  if (best_entry == RESOCT_PAGE_UNMAPPED_WORD) return RESOCT_CH_NONE;
  return resoct_entry_value(s, best_entry, resoct_read_level(best_level), bs, f.halo, best_brick,
                            cell, frac, value, st);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_CHANNEL_SAMPLE_GLSL_H
