// resoct kernel: the lens, an oriented box inside which the scene's channels are volume-rendered
// as usual; outside, per channel, nothing or another (coarser) level range. See docs/rendering.md
// ("Slices and lens").
//
// The lens is applied per ray as interval clipping: the ray meets the box in [t_in, t_out), and
// the march switches the slot table's bank at those parameters (bank 0 = the scene's channels,
// bank 1 at offset slot_count = the outside behaviour: vis_bins 0 for a hidden channel, the
// outside level range otherwise). Requests come only from what is sampled, so a lens in a huge
// volume with hidden outsides pages in just its neighbourhood.
//
// Precision: the centre is an exact level-0 cell plus a fraction like the eye, so the offset from
// the ray origin is an exact integer difference plus a small float; lens_matrix maps a voxel-space
// offset to lens coordinates where the box is [-1, 1]^3.
#ifndef RESOCT_KERNEL_LENS_GLSL_H
#define RESOCT_KERNEL_LENS_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/ray.glsl.h"

RESOCT_KERNEL_BEGIN

/// Row i of the lens matrix.
RESOCT_FN vec3 resoct_lens_row(RESOCT_FRAME_IN f, uint i) {
  return vec3(f.lens_matrix[3u * i], f.lens_matrix[3u * i + 1u], f.lens_matrix[3u * i + 2u]);
}

/// Lens coordinates of a voxel-space vector.
RESOCT_FN vec3 resoct_lens_apply(RESOCT_FRAME_IN f, vec3 v) {
  RESOCT_PRECISE vec3 r = vec3(dot(resoct_lens_row(f, 0u), v), dot(resoct_lens_row(f, 1u), v),
                               dot(resoct_lens_row(f, 2u), v));
  return r;
}

/// (t_in, t_out) of the ray origin_cell + origin_frac + t * dir_vox with the lens box; empty
/// (t_in >= t_out) when it misses.
RESOCT_FN vec2 resoct_lens_interval(RESOCT_FRAME_IN f, ivec3 origin_cell, vec3 origin_frac,
                                    vec3 dir_vox) {
  ivec3 lens_cell = ivec3(f.lens_cell_x, f.lens_cell_y, f.lens_cell_z);
  RESOCT_PRECISE vec3 rel = vec3(origin_cell - lens_cell) +
                            (origin_frac - vec3(f.lens_frac_x, f.lens_frac_y, f.lens_frac_z));
  return resoct_ray_box(resoct_lens_apply(f, rel), resoct_lens_apply(f, dir_vox), vec3(-1.0f),
                        vec3(1.0f));
}

/// Visible-channel mask of one bank of the slot table (bank = 0 or slot_count).
RESOCT_FN uint resoct_bank_live(uint bank, uint n) {
  uint live = 0u;
  for (uint i = 0u; i < n; ++i) {
    if (resoct_read_slot(bank + i).vis_bins != 0u) live = live | (1u << i);
  }
  return live;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_LENS_GLSL_H
