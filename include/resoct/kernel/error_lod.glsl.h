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
// qualify) and, in residency mode, by the octree with the margin of the coarsest level. With
// lod_error_code 0 it reads nothing.
#ifndef RESOCT_KERNEL_ERROR_LOD_GLSL_H
#define RESOCT_KERNEL_ERROR_LOD_GLSL_H

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/sample.glsl.h"

RESOCT_KERNEL_BEGIN

/// The level channel `s` samples at the level-0 cell whose footprint target is `target`:
/// `target` when error-bounded LOD is off, else the coarsest level in [finest_level,
/// coarsest_level] whose brick there is UNMAPPED, or MAPPED or HOMOGENEOUS with an error code of
/// at least s.lod_error_code (finest_level when none is).
RESOCT_FN uint resoct_error_bounded_level(RESOCT_IN(ResoctSampleParams) f,
                                          RESOCT_IN(ResoctSlotInfo) s, uint target, ivec3 cell) {
  if (s.lod_error_code == 0u) return target;
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

/// The finest and the coarsest level channel `s` may sample when its footprint target is
/// `target`: the target, or with error-bounded LOD the channel's level range (residency mode's
/// depth cap follows the finest, its culling margin must cover the coarsest).
RESOCT_FN uint resoct_error_bounded_finest(RESOCT_IN(ResoctSlotInfo) s, uint target) {
  return s.lod_error_code == 0u ? target : min(target, s.finest_level);
}
RESOCT_FN uint resoct_error_bounded_coarsest(RESOCT_IN(ResoctSlotInfo) s, uint target) {
  return s.lod_error_code == 0u ? target : max(target, s.coarsest_level);
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_ERROR_LOD_GLSL_H
