// resoct kernel: error-bounded level of detail (docs/rendering.md "Error-bounded LOD").
//
// The LOD rule of step.glsl.h picks each channel's target level from the pixel footprint alone.
// With a scene's lod_error_color > 0 the host sets ResoctSlotInfo.lod_error_code to the least
// page-entry error code (kernel/page_entry.glsl.h) whose down-sampling error, through the
// transfer function's steepest slope, stays within that colour error, and the level comes from
// the data instead: the coarsest level of the channel whose brick at the position has such a
// code, coarser than the footprint's target where the data is smooth, finer where it shows
// detail. The footprint rule still sets the sampling step (the LOD floor, frame_tables.cpp).
//
// The search runs from the channel's coarsest level down and ends at the first level whose
// brick qualifies or is not resident (then that level is the target: requested and substituted
// as any missing target is, so a view refines as bricks and their errors arrive). So the choice
// depends only on the entries of the chosen level and the coarser ones, which are the same
// everywhere in the chosen brick: the decision holds over that brick, images do not depend on
// where decisions fall, and a converged image does not depend on which other bricks happened
// to be loaded before. Empty space is culled by the EMPTY bricks the search passes (they never
// qualify) and, in residency mode, by the octree with the margin of the levels chosen at the
// decision, inside the box where those choices hold (resoct_error_bounded_factor). With
// lod_error_code 0 it reads nothing; the per-mode plain kernels of the CPU backend carry none of
// it (RESOCT_FX_ERROR_LOD).
#ifndef RESOCT_KERNEL_ERROR_LOD_GLSL_H
#define RESOCT_KERNEL_ERROR_LOD_GLSL_H

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/sample.glsl.h"

RESOCT_KERNEL_BEGIN

/// Whether channel `s` chooses its levels by error (its scene asks, and the kernel
/// specialization carries it: RESOCT_FX_ERROR_LOD, kernel/effects.glsl.h).
RESOCT_FX_FN bool resoct_error_bounded_on(RESOCT_IN(ResoctSlotInfo) s) {
  return RESOCT_FX_ERROR_LOD && s.lod_error_code != 0u;
}

/// The level channel `s` samples at the level-0 cell whose footprint target is `target`:
/// `target` when error-bounded LOD is off, else the coarsest level in [finest_level,
/// coarsest_level] whose brick there is UNMAPPED, or MAPPED or HOMOGENEOUS with an error code of
/// at least s.lod_error_code (finest_level when none is).
RESOCT_FX_FN uint resoct_error_bounded_level(RESOCT_IN(ResoctSampleParams) f,
                                             RESOCT_IN(ResoctSlotInfo) s, uint target, ivec3 cell) {
  if (!RESOCT_FX(resoct_error_bounded_on)(s)) return target;
  uvec3 bs = resoct_frame_brick_size(f);
  for (uint l = max(s.coarsest_level, s.finest_level); l > s.finest_level; l = l - 1u) {
    RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(l);
    uint e = resoct_page_entry_of(s.slot, l, f.level_count, L, resoct_brick_at(L, bs, cell));
    if (resoct_page_state(e) == RESOCT_PAGE_STATE_UNMAPPED ||
        resoct_page_error_code(e) >= s.lod_error_code) {
      return l;
    }
  }
  return s.finest_level;
}

/// Residency mode's culling with error-bounded LOD: the factor of the coarsest level a live
/// channel (bank `bank`) samples at the cell, the footprint's level `lod` for channels without
/// the bound, and [lo, hi) clipped to the box where each bounded channel's choice holds: the
/// chosen level's brick, or where the finest level was chosen because no coarser one
/// qualifies, the brick of the next coarser level (every position in it finds the same entries
/// above the finest). The node classes may cull with that factor's margin inside the box;
/// elsewhere in a culled node a channel could choose a coarser level, whose samples reach
/// farther.
RESOCT_FX_FN uvec3 resoct_error_bounded_factor(RESOCT_IN(ResoctSampleParams) f, uint bank, uint n,
                                               uint live, uint lod, ivec3 cell,
                                               RESOCT_INOUT(ivec3) lo, RESOCT_INOUT(ivec3) hi) {
  uvec3 bs = resoct_frame_brick_size(f);
  uvec3 factor = uvec3(0u);
  for (uint c = 0u; c < n; ++c) {
    if (((live >> c) & 1u) == 0u) continue;
    RESOCT_IN(ResoctSlotInfo) s = resoct_read_slot(bank + c);
    uint l = RESOCT_FX(resoct_error_bounded_level)(
        f, s, resoct_channel_level(lod, s.finest_level, s.coarsest_level), cell);
    factor = max(factor, resoct_level_factor(resoct_read_level(l)));
    if (!RESOCT_FX(resoct_error_bounded_on)(s)) continue;
    uint holds = l == s.finest_level ? min(l + 1u, max(s.coarsest_level, l)) : l;
    RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(holds);
    resoct_box_clip_brick(lo, hi, L, bs, resoct_brick_at(L, bs, cell));
  }
  return factor;
}

/// The finest and the coarsest level channel `s` may sample when its footprint target is
/// `target`: the target, or with error-bounded LOD the channel's level range (residency mode's
/// depth cap follows the finest; a node that contains the coarsest's bricks contains the
/// sources).
RESOCT_FX_FN uint resoct_error_bounded_finest(RESOCT_IN(ResoctSlotInfo) s, uint target) {
  return RESOCT_FX(resoct_error_bounded_on)(s) ? min(target, s.finest_level) : target;
}
RESOCT_FX_FN uint resoct_error_bounded_coarsest(RESOCT_IN(ResoctSlotInfo) s, uint target) {
  return RESOCT_FX(resoct_error_bounded_on)(s) ? max(target, s.coarsest_level) : target;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_ERROR_LOD_GLSL_H
