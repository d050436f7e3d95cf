// resoct kernel: what one channel yields at one sample in each render mode (residency with
// substitution, page table, standard octree), plus the request strategy. Used by
// traverse.glsl.h; see docs/rendering.md ("Traversal").
//
// Accessors: as listed in traverse.glsl.h (pages, levels, nodes, cache, requests, used slots).
#ifndef RESOCT_KERNEL_CHANNEL_SAMPLE_GLSL_H
#define RESOCT_KERNEL_CHANNEL_SAMPLE_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/node_class.glsl.h"
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

RESOCT_FN ResoctSampleParams resoct_sample_params(RESOCT_FRAME_IN f) {
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

RESOCT_FN uvec3 resoct_frame_brick_size(RESOCT_IN(ResoctSampleParams) f) {
  return uvec3(f.brick_x, f.brick_y, f.brick_z);
}

/// Levels a slot may use as a bitmask: [finest, coarsest].
RESOCT_FN uint resoct_allowed_levels(RESOCT_IN(ResoctSlotInfo) s) {
  uint hi = s.coarsest_level >= 31u ? 0xFFFFFFFFu : ((2u << s.coarsest_level) - 1u);
  return hi & ~((1u << s.finest_level) - 1u);
}

/// Entry and exit offsets (t relative to the position cell + frac) of the ray with the integer
/// box [lo, hi), for the ray's reciprocal direction in level-0 voxels `inv_vox`
/// (resoct_ray_inverse, once per ray), computed in box-local coordinates so that huge axes
/// neither stall nor overshoot. Sizes are taken as unsigned differences, so an unclipped axis
/// (corners at +-(2^31 - 1)) is fine.
RESOCT_FN vec2 resoct_box_offsets(ivec3 cell, vec3 frac, vec3 inv_vox, ivec3 lo, ivec3 hi) {
  return resoct_ray_node_local(resoct_relative_origin(cell, frac, lo), inv_vox,
                               vec3(uvec3(hi) - uvec3(lo)));
}

/// Offset of t from the position at which the ray leaves the integer box [lo, hi) (which holds
/// the position); see resoct_box_offsets.
RESOCT_FN float resoct_box_exit_t(ivec3 cell, vec3 frac, vec3 inv_vox, ivec3 lo, ivec3 hi) {
  return resoct_ray_box_exit_inv(resoct_relative_origin(cell, frac, lo), inv_vox, vec3(0.0f),
                                 vec3(uvec3(hi) - uvec3(lo)));
}

/// resoct_box_exit_t for the box [lo, lo + size) (a brick or node inside the volume).
RESOCT_FN float resoct_box_exit(ivec3 cell, vec3 frac, vec3 inv_vox, ivec3 lo, vec3 size) {
  return resoct_box_exit_t(cell, frac, inv_vox, lo, lo + ivec3(size));
}

/// Offset of t from the position at which the ray enters the integer box [lo, hi) ahead of it;
/// infinite when it never does, 0 when the position is already inside.
RESOCT_FN float resoct_box_entry_t(ivec3 cell, vec3 frac, vec3 inv_vox, ivec3 lo, ivec3 hi) {
  vec2 ie = resoct_box_offsets(cell, frac, inv_vox, lo, hi);
  if (!(ie.x < ie.y) || !(ie.y > 0.0f)) return RESOCT_RAY_T_INF;
  return max(ie.x, 0.0f);
}

/// Whether an EMPTY page entry renders: a brick of zeros where the transfer function shows 0
/// (ResoctSlotInfo.zero_visible). A brick without finite values never does.
RESOCT_FN bool resoct_empty_page_shows(RESOCT_IN(ResoctSlotInfo) s, uint entry) {
  return s.zero_visible != 0u && resoct_page_payload(entry) == 0u;
}

/// What one channel yields over a ray *segment*: the part of the ray in which everything the
/// channel's lookup decides (level, page entry, substitution, requests, used slot) stays the same.
/// The march (traverse.glsl.h) decides a source once per segment and then only samples it.
struct ResoctSource {
  uint kind;        // RESOCT_CH_NONE (nothing), RESOCT_CH_VALUE (constant `value` or, with
                    // cache_slot != RESOCT_SOURCE_NO_SLOT, a mapped brick), RESOCT_CH_EMPTY
  float value;      // the constant (normalized) value
  uint cache_slot;  // mapped brick's cache slot, or RESOCT_SOURCE_NO_SLOT
  uint level;       // level of the page entry (target or substitute)
  // Per-segment constants of the sample path, so that a sample reads no table: the padded-brick
  // position of level-0 position (cell, frac) is (cell - core_lo + frac) * scale + halo.
  ivec3 core_lo;  // level-0 corner of the brick's core
  vec3 scale;     // 2^-factor_log2 per axis
  uint tf_slot;   // transfer-function slot (ResoctSlotInfo.slot)
  float range_lo;
  float inv_range_width;
  // Along the march (resoct_source_along_ray): the padded-brick position at ray parameter t is
  // ray_base + t * ray_dir, so a sample computes no cell, fraction or floor.
  vec3 ray_base;
  vec3 ray_dir;
};

RESOCT_CONST(uint, RESOCT_SOURCE_NO_SLOT, 0xFFFFFFFFu);

RESOCT_FN ResoctSource resoct_source_of(uint kind, float value) {
  ResoctSource src;
  src.kind = kind;
  src.value = value;
  src.cache_slot = RESOCT_SOURCE_NO_SLOT;
  src.level = 0u;
  src.core_lo = ivec3(0);
  src.scale = vec3(1.0f);
  src.tf_slot = 0u;
  src.range_lo = 0.0f;
  src.inv_range_width = 1.0f;
  src.ray_base = vec3(0.0f);
  src.ray_dir = vec3(0.0f);
  return src;
}

/// A constant source of slot `s`.
RESOCT_FN ResoctSource resoct_source_value(RESOCT_IN(ResoctSlotInfo) s, float value) {
  ResoctSource src = resoct_source_of(RESOCT_CH_VALUE, value);
  src.tf_slot = s.slot;
  return src;
}

/// Whether the cell lies in the integer box [lo, hi) (unsigned differences: two operations per
/// axis, no overflow for boxes spanning the whole int range).
RESOCT_FN bool resoct_in_box(ivec3 cell, ivec3 lo, ivec3 hi) {
  return uint(cell.x) - uint(lo.x) < uint(hi.x) - uint(lo.x) &&
         uint(cell.y) - uint(lo.y) < uint(hi.y) - uint(lo.y) &&
         uint(cell.z) - uint(lo.z) < uint(hi.z) - uint(lo.z);
}

/// Shrinks the integer box [lo, hi) to its intersection with [blo, bhi).
RESOCT_FN void resoct_box_clip(RESOCT_INOUT(ivec3) lo, RESOCT_INOUT(ivec3) hi, ivec3 blo,
                               ivec3 bhi) {
  lo = max(lo, blo);
  hi = min(hi, bhi);
}

/// Clips [lo, hi) to the level-0 box of a brick of level L.
RESOCT_FN void resoct_box_clip_brick(RESOCT_INOUT(ivec3) lo, RESOCT_INOUT(ivec3) hi,
                                     RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size, uvec3 brick) {
  ivec3 blo = resoct_brick_lo0(L, brick_size, brick);
  resoct_box_clip(lo, hi, blo, blo + ivec3(resoct_brick_size0(L, brick_size)));
}

/// The source of a present (not UNMAPPED) page entry of `level`; marks a mapped brick's cache
/// slot used (once per segment).
RESOCT_FN ResoctSource resoct_entry_source(RESOCT_IN(ResoctSlotInfo) s, uint entry, uint level,
                                           RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size,
                                           uvec3 brick) {
  uint state = resoct_page_state(entry);
  ResoctSource src = resoct_source_of(RESOCT_CH_NONE, 0.0f);
  if (state == RESOCT_PAGE_STATE_EMPTY) {
    src = resoct_empty_page_shows(s, entry) ? resoct_source_value(s, s.zero_value)
                                            : resoct_source_of(RESOCT_CH_EMPTY, 0.0f);
  } else if (state == RESOCT_PAGE_STATE_HOMOGENEOUS) {
    src = resoct_source_value(s, resoct_page_homogeneous_value(entry));
  } else if (state == RESOCT_PAGE_STATE_MAPPED) {
    src = resoct_source_value(s, 0.0f);
    src.cache_slot = resoct_page_cache_slot(entry);
    uvec3 fl = resoct_level_factor(L);
    src.core_lo = resoct_brick_lo0(L, brick_size, brick);
    src.scale = vec3(1.0f / float(1u << fl.x), 1.0f / float(1u << fl.y), 1.0f / float(1u << fl.z));
    src.range_lo = s.range_lo;
    src.inv_range_width = s.inv_range_width;
    resoct_mark_used(src.cache_slot);
  }
  src.level = level;
  return src;
}

/// The value of a source at a level-0 position inside its segment: RESOCT_CH_VALUE with `value`
/// (a trilinear sample of a mapped brick through its halo, or the constant), else the kind.
RESOCT_FN uint resoct_source_sample(RESOCT_IN(ResoctSampleParams) f, RESOCT_IN(ResoctSource) src,
                                    ivec3 cell, vec3 frac, RESOCT_OUT(float) value,
                                    RESOCT_INOUT(ResoctRayStats) st) {
  value = src.value;
  if (src.kind != RESOCT_CH_VALUE || src.cache_slot == RESOCT_SOURCE_NO_SLOT) return src.kind;
  st.brick_accesses = st.brick_accesses + 1u;
  vec3 padded = (vec3(cell - src.core_lo) + frac) * src.scale + vec3(float(f.halo));
  value = resoct_normalize_value(resoct_sample_cache(src.cache_slot, padded), src.range_lo,
                                 src.inv_range_width);
  return RESOCT_CH_VALUE;
}

/// Prepares a mapped source for resoct_source_sample_t along the ray origin_cell + origin_frac +
/// t * dir_vox: the padded position is affine in t. The integer part of the offset from the brick
/// is exact, so rounding is relative to the distance from the ray origin, as for positions.
/// In place: in C++ a by-value copy of the record, written back whole, made the store of the
/// new fields and the reload of the record overlap (a store-forwarding stall at every decision).
RESOCT_FN void resoct_source_along_ray(RESOCT_INOUT(ResoctSource) src, ivec3 origin_cell,
                                       vec3 origin_frac, vec3 dir_vox, uint halo) {
  src.ray_base = (vec3(origin_cell - src.core_lo) + origin_frac) * src.scale + vec3(float(halo));
  src.ray_dir = dir_vox * src.scale;
}

/// resoct_source_sample at ray parameter t, after resoct_source_along_ray.
RESOCT_FN uint resoct_source_sample_t(RESOCT_IN(ResoctSource) src, float t, RESOCT_OUT(float) value,
                                      RESOCT_INOUT(ResoctRayStats) st) {
  value = src.value;
  if (src.kind != RESOCT_CH_VALUE || src.cache_slot == RESOCT_SOURCE_NO_SLOT) return src.kind;
  st.brick_accesses = st.brick_accesses + 1u;
  value =
      resoct_normalize_value(resoct_sample_cache(src.cache_slot, src.ray_base + t * src.ray_dir),
                             src.range_lo, src.inv_range_width);
  return RESOCT_CH_VALUE;
}

/// Requests the target brick of a missing sample (once per ray and slot while the key repeats)
/// and, greedy, every coarser level's brick at the position up to the first present one.
RESOCT_FN void resoct_request_missing(RESOCT_IN(ResoctSampleParams) f, RESOCT_IN(ResoctSlotInfo) s,
                                      uint level, ivec3 cell, RESOCT_INOUT(uint) last_key,
                                      RESOCT_INOUT(ResoctRayStats) st) {
  uvec3 bs = resoct_frame_brick_size(f);
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(level);
  uint key =
      resoct_brick_request_key(s.slot, level, f.level_count, L, resoct_brick_at(L, bs, cell));
  if (key == last_key) return;
  last_key = key;
  resoct_report_request(key);
  st.requests = st.requests + 1u;
  if (f.request_greedy == 0u) return;
  for (uint l = level + 1u; l <= s.coarsest_level; ++l) {
    RESOCT_IN(ResoctLevelInfo) Lc = resoct_read_level(l);
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
/// finer, checking the actual page entry at the position for each candidate. [lo, hi) is clipped
/// to the box in which this answer holds: the target brick (coarser bricks contain it; requests
/// and greedy requests are the same everywhere in it), and for a substitute also the node (its
/// residency word chose the candidates) and a finer substitute's brick.
RESOCT_FN ResoctSource resoct_residency_source(RESOCT_IN(ResoctSampleParams) f,
                                               RESOCT_IN(ResoctSlotInfo) s, uint node,
                                               ivec3 node_lo, ivec3 node_hi, uint target,
                                               ivec3 cell, RESOCT_INOUT(uint) last_key,
                                               RESOCT_INOUT(ivec3) lo, RESOCT_INOUT(ivec3) hi,
                                               RESOCT_INOUT(ResoctRayStats) st) {
  uvec3 bs = resoct_frame_brick_size(f);
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(target);
  uvec3 b = resoct_brick_at(L, bs, cell);
  resoct_box_clip_brick(lo, hi, L, bs, b);
  uint e = resoct_page_entry_of(s.slot, target, f.level_count, L, b);
  if (resoct_page_state(e) != RESOCT_PAGE_STATE_UNMAPPED) {
    return resoct_entry_source(s, e, target, L, bs, b);
  }
  resoct_request_missing(f, s, target, cell, last_key, st);
  resoct_box_clip(lo, hi, node_lo, node_hi);
  uint r =
      resoct_read_node(resoct_node_base(node, s.slot, f.node_slot_count) + RESOCT_NODE_RESIDENCY) &
      resoct_allowed_levels(s);
  if (r == 0u) return resoct_source_of(RESOCT_CH_NONE, 0.0f);
  int l = resoct_node_next_coarser(r, target);
  while (l >= 0) {
    uint lu = uint(l);
    RESOCT_IN(ResoctLevelInfo) Lc = resoct_read_level(lu);
    uvec3 bc = resoct_brick_at(Lc, bs, cell);
    uint ec = resoct_page_entry_of(s.slot, lu, f.level_count, Lc, bc);
    if (resoct_page_state(ec) != RESOCT_PAGE_STATE_UNMAPPED) {
      return resoct_entry_source(s, ec, lu, Lc, bs, bc);
    }
    l = resoct_node_next_coarser(r, lu);
  }
  l = resoct_node_next_finer(r, target);
  while (l >= 0) {
    uint lu = uint(l);
    RESOCT_IN(ResoctLevelInfo) Lf = resoct_read_level(lu);
    uvec3 bf = resoct_brick_at(Lf, bs, cell);
    resoct_box_clip_brick(lo, hi, Lf, bs, bf);
    uint ef = resoct_page_entry_of(s.slot, lu, f.level_count, Lf, bf);
    if (resoct_page_state(ef) != RESOCT_PAGE_STATE_UNMAPPED) {
      return resoct_entry_source(s, ef, lu, Lf, bs, bf);
    }
    l = resoct_node_next_finer(r, lu);
  }
  return resoct_source_of(RESOCT_CH_NONE, 0.0f);
}

/// Residency mode at one position (slices, shadow rays): resoct_residency_source, sampled.
RESOCT_FN uint resoct_residency_channel(RESOCT_IN(ResoctSampleParams) f,
                                        RESOCT_IN(ResoctSlotInfo) s, uint node, uint target,
                                        ivec3 cell, vec3 frac, RESOCT_INOUT(uint) last_key,
                                        RESOCT_OUT(float) value, RESOCT_INOUT(ResoctRayStats) st) {
  ivec3 lo = cell;
  ivec3 hi = cell + ivec3(1);
  ResoctSource src =
      resoct_residency_source(f, s, node, lo, hi, target, cell, last_key, lo, hi, st);
  return resoct_source_sample(f, src, cell, frac, value, st);
}

/// Page-table mode, one channel: the target level or nothing (requested); [lo, hi) is clipped to
/// the target brick. `skip_exit` receives the exit offset of an EMPTY brick.
RESOCT_FN ResoctSource resoct_pagetable_source(RESOCT_IN(ResoctSampleParams) f,
                                               RESOCT_IN(ResoctSlotInfo) s, uint target, ivec3 cell,
                                               vec3 frac, vec3 inv_vox, RESOCT_INOUT(uint) last_key,
                                               RESOCT_INOUT(ivec3) lo, RESOCT_INOUT(ivec3) hi,
                                               RESOCT_OUT(float) skip_exit,
                                               RESOCT_INOUT(ResoctRayStats) st) {
  skip_exit = 0.0f;
  uvec3 bs = resoct_frame_brick_size(f);
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(target);
  uvec3 b = resoct_brick_at(L, bs, cell);
  resoct_box_clip_brick(lo, hi, L, bs, b);
  uint e = resoct_page_entry_of(s.slot, target, f.level_count, L, b);
  if (resoct_page_state(e) == RESOCT_PAGE_STATE_UNMAPPED) {
    resoct_request_missing(f, s, target, cell, last_key, st);
    return resoct_source_of(RESOCT_CH_NONE, 0.0f);
  }
  ResoctSource src = resoct_entry_source(s, e, target, L, bs, b);
  if (src.kind == RESOCT_CH_EMPTY) {
    skip_exit =
        resoct_box_exit(cell, frac, inv_vox, resoct_brick_lo0(L, bs, b), resoct_brick_size0(L, bs));
  }
  return src;
}

/// Standard-octree mode, one channel: walk the levels from the slot's coarsest to the target at
/// the position (one node per level: paper 000 §8's octree, whose nodes are the bricks); the
/// first missing level is requested and ends the walk, the finest present level above it is
/// sampled. A level ends the walk with the channel empty there when its brick is an EMPTY page
/// that does not show, or, with the residency mode's culling data, when the octree node that is
/// this brick (ResoctLevelInfo.node_depth) has a record the transfer function cannot see
/// (resoct_node_class) and the position lies in the brick shrunk by that level's margin
/// (resoct_culling_margin: a sample there of this level, the coarsest the walk can sample in the
/// brick, or of a finer one reads only voxels inside the node's record). Such a node without a
/// record is requested (once per run of requests for it along the ray: `last_node`) and does not
/// cull. Every mapped brick of the walk is marked used: the walk needs the whole path resident.
/// [lo, hi) is clipped to the target brick, which every brick of the walk contains.
RESOCT_FN ResoctSource resoct_octree_source(RESOCT_IN(ResoctSampleParams) f,
                                            RESOCT_IN(ResoctSlotInfo) s, uint target,
                                            uint start_depth, ivec3 cell, vec3 frac, vec3 inv_vox,
                                            RESOCT_INOUT(uint) last_key,
                                            RESOCT_INOUT(uint) last_node, RESOCT_INOUT(ivec3) lo,
                                            RESOCT_INOUT(ivec3) hi, RESOCT_OUT(float) skip_exit,
                                            RESOCT_INOUT(ResoctRayStats) st) {
  skip_exit = 0.0f;
  uvec3 bs = resoct_frame_brick_size(f);
  RESOCT_IN(ResoctLevelInfo) Lt = resoct_read_level(target);
  resoct_box_clip_brick(lo, hi, Lt, bs, resoct_brick_at(Lt, bs, cell));
  uint best_entry = RESOCT_PAGE_UNMAPPED_WORD;
  uint best_level = 0u;
  uvec3 best_brick = uvec3(0u);
  uint l = s.coarsest_level + 1u;
  while (l > target) {
    l = l - 1u;
    st.nodes = st.nodes + 1u;
    RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(l);
    uvec3 b = resoct_brick_at(L, bs, cell);
    uint e = resoct_page_entry_of(s.slot, l, f.level_count, L, b);
    uint state = resoct_page_state(e);
    if (state == RESOCT_PAGE_STATE_UNMAPPED) {
      resoct_request_missing(f, s, l, cell, last_key, st);
      break;
    }
    ivec3 blo = resoct_brick_lo0(L, bs, b);
    vec3 bsize = resoct_brick_size0(L, bs);
    if (state == RESOCT_PAGE_STATE_EMPTY && !resoct_empty_page_shows(s, e)) {
      skip_exit = resoct_box_exit(cell, frac, inv_vox, blo, bsize);
      return resoct_source_of(RESOCT_CH_EMPTY, 0.0f);
    }
    if (state == RESOCT_PAGE_STATE_MAPPED) resoct_mark_used(resoct_page_cache_slot(e));
    if (L.node_depth != RESOCT_NONE_U) {
      RESOCT_IN(ResoctDepthInfo) D = resoct_read_depth(L.node_depth);
      uint node =
          resoct_node_index(L.node_depth, resoct_node_coord(D, cell), resoct_depth_count_log2(D));
      uint cls = resoct_node_class(node, s, f.node_slot_count);
      if (cls == RESOCT_NODE_CLASS_INVALID) {
        if (L.node_depth >= start_depth && node != last_node) {
          last_node = node;
          resoct_report_node_request(node);
          st.requests = st.requests + 1u;
        }
      } else if (cls == RESOCT_NODE_CLASS_EMPTY) {
        ivec3 margin = resoct_culling_margin(resoct_level_factor(L));
        ivec3 ilo = blo + margin;
        ivec3 ihi = blo + ivec3(bsize) - margin;
        if (resoct_in_box(cell, ilo, ihi)) {
          skip_exit = resoct_box_exit(cell, frac, inv_vox, ilo, vec3(ihi - ilo));
          return resoct_source_of(RESOCT_CH_EMPTY, 0.0f);
        }
      }
    }
    best_entry = e;
    best_level = l;
    best_brick = b;
  }
  if (best_entry == RESOCT_PAGE_UNMAPPED_WORD) return resoct_source_of(RESOCT_CH_NONE, 0.0f);
  return resoct_entry_source(s, best_entry, best_level, resoct_read_level(best_level), bs,
                             best_brick);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_CHANNEL_SAMPLE_GLSL_H
