// resoct kernel: primary rays from the per-frame camera, in box space and in voxel space.
//
// Pixel (px, py) shoots through its centre (px + 0.5, py + 0.5), row 0 at the top, exactly as
// resoct::CameraRays does in double: image-plane coordinates u = (2x − width) / height · hh and
// v = (height − 2y) / height · hh with hh = half_height. Perspective rays start at the eye with
// direction normalize(forward + u·right + v·up); orthographic rays start at eye + u·right + v·up
// with direction forward. An accumulated frame moves the centre by its sub-pixel jitter
// (jitter_x, jitter_y); without one they are 0, and px + 0.5 + 0 is exactly px + 0.5.
//
// The voxel-space origin is the exact eye cell (host-split in double) plus a float fraction; the
// orthographic offset u·right + v·up is added to the fraction and re-split, so its rounding is
// relative to the offset, not to the volume size.
#ifndef RESOCT_KERNEL_CAMERA_RAY_GLSL_H
#define RESOCT_KERNEL_CAMERA_RAY_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/ray.glsl.h"

RESOCT_KERNEL_BEGIN

/// Level-0 voxels per box unit as a vector.
RESOCT_FN vec3 resoct_frame_voxels_per_box(RESOCT_FRAME_IN f) {
  return vec3(f.voxels_per_box_x, f.voxels_per_box_y, f.voxels_per_box_z);
}

/// The ray of pixel (px, py): unit direction in box space, and its origin in voxel space split
/// into an exact cell and a fraction in [0, 1).
RESOCT_FN void resoct_camera_ray(RESOCT_FRAME_IN f, uint px, uint py, RESOCT_OUT(vec3) dir_box,
                                 RESOCT_OUT(ivec3) origin_cell, RESOCT_OUT(vec3) origin_frac) {
  // Every operation here is precise and every quotient a product with a correctly rounded
  // reciprocal, so that a ray is the same float on every backend: a device compiler may fuse a
  // multiply-add, divide as x * rcp(y) or normalize with an approximate inverse square root, and
  // a last-bit difference in a ray's direction moves its step, entry and samples.
  RESOCT_PRECISE float inv_rows = 1.0f / float(f.height);
  RESOCT_PRECISE float cx = 2.0f * (float(px) + 0.5f + f.jitter_x) - float(f.width);
  RESOCT_PRECISE float cy = float(f.height) - 2.0f * (float(py) + 0.5f + f.jitter_y);
  RESOCT_PRECISE float u = cx * inv_rows * f.half_height;
  RESOCT_PRECISE float v = cy * inv_rows * f.half_height;
  vec3 fw = vec3(f.forward_x, f.forward_y, f.forward_z);
  vec3 rt = vec3(f.right_x, f.right_y, f.right_z);
  vec3 up = vec3(f.up_x, f.up_y, f.up_z);
  origin_cell = ivec3(f.eye_cell_x, f.eye_cell_y, f.eye_cell_z);
  origin_frac = vec3(f.eye_frac_x, f.eye_frac_y, f.eye_frac_z);
  RESOCT_PRECISE vec3 ur = u * rt;
  RESOCT_PRECISE vec3 vu = v * up;
  RESOCT_PRECISE vec3 offset = ur + vu;
  if (f.projection == RESOCT_PROJECTION_PERSPECTIVE) {
    RESOCT_PRECISE vec3 d = fw + offset;
    RESOCT_PRECISE vec3 sq = d * d;
    RESOCT_PRECISE float len2 = (sq.x + sq.y) + sq.z;
    RESOCT_PRECISE float inv_len = 1.0f / sqrt(len2);
    dir_box = d * inv_len;
  } else {
    dir_box = fw;
    RESOCT_PRECISE vec3 shift = offset * resoct_frame_voxels_per_box(f);
    RESOCT_PRECISE vec3 moved = origin_frac + shift;
    origin_frac = moved;
    resoct_split_normalize(origin_cell, origin_frac);
  }
}

/// View depth (distance along forward) of the point at parameter t of a camera ray.
RESOCT_FN float resoct_view_depth(RESOCT_FRAME_IN f, vec3 dir_box, float t) {
  if (f.projection != RESOCT_PROJECTION_PERSPECTIVE) return 0.0f;
  return t * dot(dir_box, vec3(f.forward_x, f.forward_y, f.forward_z));
}

/// Position at parameter t (box units) of the ray origin_cell + origin_frac + t · dir_vox, split
/// into a cell and a fraction in [0, 1). Rounding is relative to the distance from the origin.
RESOCT_FN void resoct_ray_position(ivec3 origin_cell, vec3 origin_frac, vec3 dir_vox, float t,
                                   RESOCT_OUT(ivec3) cell, RESOCT_OUT(vec3) frac) {
  cell = origin_cell;
  // Precise: a device compiler may otherwise fuse this into a multiply-add, rounded once where
  // the host rounds twice, and the backends' positions (and the nodes and bricks they fall in)
  // would differ in the last bit.
  RESOCT_PRECISE vec3 along = t * dir_vox;
  RESOCT_PRECISE vec3 moved = origin_frac + along;
  frac = moved;
  resoct_split_normalize(cell, frac);
  // floor(frac) can leave frac == 1.0 after rounding of frac - floor(frac); keep it half-open.
  if (frac.x >= 1.0f) {
    cell.x = cell.x + 1;
    frac.x = 0.0f;
  }
  if (frac.y >= 1.0f) {
    cell.y = cell.y + 1;
    frac.y = 0.0f;
  }
  if (frac.z >= 1.0f) {
    cell.z = cell.z + 1;
    frac.z = 0.0f;
  }
}

/// Clamps a position into the volume [0, extent) (drift of a sample at the border by rounding).
RESOCT_FN void resoct_clamp_position(RESOCT_FRAME_IN f, RESOCT_INOUT(ivec3) cell,
                                     RESOCT_INOUT(vec3) frac) {
  ivec3 hi = ivec3(int(f.extent_x) - 1, int(f.extent_y) - 1, int(f.extent_z) - 1);
  if (cell.x < 0) {
    cell.x = 0;
    frac.x = 0.0f;
  }
  if (cell.y < 0) {
    cell.y = 0;
    frac.y = 0.0f;
  }
  if (cell.z < 0) {
    cell.z = 0;
    frac.z = 0.0f;
  }
  if (cell.x > hi.x) {
    cell.x = hi.x;
    frac.x = 0.99999994f;
  }
  if (cell.y > hi.y) {
    cell.y = hi.y;
    frac.y = 0.99999994f;
  }
  if (cell.z > hi.z) {
    cell.z = hi.z;
    frac.z = 0.99999994f;
  }
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_CAMERA_RAY_GLSL_H
