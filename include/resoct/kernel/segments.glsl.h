// resoct kernel: cuts a ray into segments at slice planes and lens faces, so that slices and the
// lens need no per-sample work in the march (docs/rendering.md "Slices and lens").
//
// The march of traverse.glsl.h runs over [t, t_exit). With slices or a lens, t_exit is the end
// of the current segment, and when the march reaches it the loop condition calls
// resoct_segment_next, which composites the slices lying there, picks the next stop (the nearest
// slice hit, lens face or the volume exit) and the slot-table bank of the new segment (0 inside
// the lens or without one, slot_count outside). A segment without live channels is passed over
// without marching; the march restarts its step grid at each stop, and its last, shorter
// segment before a stop is opacity-corrected as at the volume exit. A plain scene pays one test
// of a frame constant per ray and one of a ray constant at its end, nothing per sample.
#ifndef RESOCT_KERNEL_SEGMENTS_GLSL_H
#define RESOCT_KERNEL_SEGMENTS_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/lens.glsl.h"
#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/slice.glsl.h"

// Once per ray, outside the march: keep these out of line in C++ so that the march loop's code
// stays as compact as without slices and lens.
#ifdef __cplusplus
#define RESOCT_SEGMENTS_FN [[gnu::noinline]] inline
#else
#define RESOCT_SEGMENTS_FN
#endif

RESOCT_KERNEL_BEGIN

struct ResoctSegments {
  uint enabled;      // 1 when the frame has slices or a lens
  uint bank;         // slot-table offset of the current segment
  uint live_in;      // live channels of bank 0 (inside the lens, or no lens)
  uint live_out;     // live channels of the outside bank
  uint slices_left;  // bit i: plane i still to composite
  float t_end;       // the volume exit
  float lens_in;     // the ray's interval in the lens (empty when it misses)
  float lens_out;
  float slice_t[RESOCT_MAX_SLICES];
  // Exchange with the march (resoct_segment_advance).
  float t;     // ray parameter
  float stop;  // end of the current segment (the march's t_exit)
  vec4 acc;    // premultiplied colour so far
  uint live;   // live channels of the current segment
  uint reset;  // 1: the bank changed, drop cached node classifications
};

/// The segments of a frame without slices and lens: one, bank 0, nothing to do at its end.
RESOCT_FN ResoctSegments resoct_segments_none(uint live) {
  ResoctSegments sg;
  sg.enabled = 0u;
  sg.bank = 0u;
  sg.live_in = live;
  sg.live_out = live;
  sg.slices_left = 0u;
  sg.t_end = 0.0f;
  sg.lens_in = RESOCT_RAY_T_INF;
  sg.lens_out = RESOCT_RAY_T_INF;
  for (uint i = 0u; i < RESOCT_MAX_SLICES; ++i) sg.slice_t[i] = RESOCT_RAY_T_INF;
  sg.t = 0.0f;
  sg.stop = 0.0f;
  sg.acc = vec4(0.0f);
  sg.live = live;
  sg.reset = 0u;
  return sg;
}

/// Sets up a ray's segments over [t, t_exit) when the frame has slices or a lens: the slice hits
/// and the lens interval. The caller then lets its first segment end at t, so that the march
/// asks for the first real segment right away.
RESOCT_SEGMENTS_FN void resoct_segments_begin(RESOCT_FRAME_IN f, RESOCT_INOUT(ResoctSegments) sg,
                                              ivec3 origin_cell, vec3 origin_frac, vec3 dir_vox,
                                              float t, float t_exit) {
  sg.enabled = 1u;
  sg.t_end = t_exit;
  uint n = min(f.slot_count, RESOCT_MAX_SLOTS);
  if (f.lens_enabled != 0u) {
    vec2 li = resoct_lens_interval(f, origin_cell, origin_frac, dir_vox);
    // A miss leaves no stop: the ray is outside the lens throughout.
    if (li.x < li.y) {
      sg.lens_in = li.x;
      sg.lens_out = li.y;
    }
    sg.live_out = resoct_bank_live(n, n);
  }
  for (uint i = 0u; i < min(f.slice_count, RESOCT_MAX_SLICES); ++i) {
    float th = resoct_slice_hit(f, i, origin_cell, origin_frac, dir_vox);
    // Half-open like the volume: a plane hit at the exit lies outside.
    if (th >= t && th < sg.t_end) {
      sg.slice_t[i] = th;
      sg.slices_left = sg.slices_left | (1u << i);
    }
  }
}

/// Called when the march reached sg.stop, the end of the current segment, with the ray's
/// accumulated colour in sg.acc and its parameter in sg.t: composites the slices up to there
/// (front to back), then opens the next segment that has live channels (sg.t, sg.stop, sg.live,
/// sg.bank; sg.reset when the bank changed). Returns false when the ray is done (volume exit, or
/// saturated). Works on sg alone so that the march's own variables never have their address
/// taken (they stay in registers on the CPU).
RESOCT_SEGMENTS_FN bool resoct_segment_next(RESOCT_FRAME_IN f, RESOCT_INOUT(ResoctSegments) sg,
                                            ivec3 origin_cell, vec3 origin_frac, vec3 dir_box,
                                            vec3 dir_vox, float dt,
                                            RESOCT_INOUT(ResoctRayStats) st) {
  float stop = sg.stop;
  sg.reset = 0u;
  // Every pass either returns or moves `stop` strictly forward to one of finitely many stops.
  while (true) {
    // Slices at or before the stop, nearest first.
    while (sg.slices_left != 0u) {
      uint best = 0u;
      float best_t = RESOCT_RAY_T_INF;
      for (uint i = 0u; i < RESOCT_MAX_SLICES; ++i) {
        if (((sg.slices_left >> i) & 1u) != 0u && sg.slice_t[i] < best_t) {
          best = i;
          best_t = sg.slice_t[i];
        }
      }
      if (best_t > stop) break;
      sg.slices_left = sg.slices_left & ~(1u << best);
      sg.acc = resoct_composite(sg.acc, resoct_slice_shade(f, best, origin_cell, origin_frac,
                                                           dir_box, dir_vox, best_t, st));
      if (resoct_saturated(sg.acc, f.ert_opacity)) return false;
    }
    if (stop >= sg.t_end) return false;
    float next = sg.t_end;
    for (uint i = 0u; i < RESOCT_MAX_SLICES; ++i) {
      if (((sg.slices_left >> i) & 1u) != 0u) next = min(next, sg.slice_t[i]);
    }
    if (sg.lens_in > stop) next = min(next, sg.lens_in);
    if (sg.lens_out > stop) next = min(next, sg.lens_out);
    float mid = 0.5f * (stop + next);
    bool inside = f.lens_enabled == 0u || (mid >= sg.lens_in && mid < sg.lens_out);
    uint bank = inside ? 0u : min(f.slot_count, RESOCT_MAX_SLOTS);
    uint bank_live = inside ? sg.live_in : sg.live_out;
    float start = max(sg.t, stop);
    if (bank_live != 0u && next - start > RESOCT_SEGMENT_EPS * dt) {
      if (bank != sg.bank) {
        sg.bank = bank;
        sg.reset = 1u;
      }
      sg.live = bank_live;
      sg.t = start;
      sg.stop = next;
      return true;
    }
    stop = next;
  }
  return false;
}

/// The loop-condition hook of the march (traverse.glsl.h): hands the march state to
/// resoct_segment_next and takes the next segment back. False when the ray is done.
RESOCT_FN bool resoct_segment_advance(RESOCT_FRAME_IN f, RESOCT_INOUT(ResoctSegments) sg,
                                      ivec3 origin_cell, vec3 origin_frac, vec3 dir_box,
                                      vec3 dir_vox, float dt, RESOCT_INOUT(float) t,
                                      RESOCT_INOUT(float) t_exit, RESOCT_INOUT(vec4) acc,
                                      RESOCT_INOUT(uint) live, RESOCT_INOUT(uint) bank,
                                      RESOCT_INOUT(uint) cached_node,
                                      RESOCT_INOUT(uvec3) cached_coord,
                                      RESOCT_INOUT(ResoctRayStats) st) {
  sg.t = t;
  sg.stop = t_exit;
  sg.acc = acc;
  bool more = resoct_segment_next(f, sg, origin_cell, origin_frac, dir_box, dir_vox, dt, st);
  acc = sg.acc;
  if (!more) return false;
  t = sg.t;
  t_exit = sg.stop;
  live = sg.live;
  bank = sg.bank;
  if (sg.reset != 0u) {
    // The residency mode's node classification depends on the bank's channels.
    cached_node = 0xFFFFFFFFu;
    cached_coord = uvec3(0xFFFFFFFFu);
  }
  return true;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_SEGMENTS_GLSL_H
