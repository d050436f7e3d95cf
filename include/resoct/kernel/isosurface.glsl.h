// resoct kernel: exact ray/isosurface intersection on trilinear cells (paper 004 §5.5).
//
// The march brackets a crossing of the isovalue between two consecutive samples of an iso
// channel (a sign change of value − iso). resoct_iso_refine then walks the trilinear cells of
// the sample's level that the ray crosses inside the bracket, in ray order. Inside one cell the
// field along the ray is exactly a cubic in t (each trilinear weight is linear in t), so four
// samples of the cell's interval determine it; the first root of that cubic in the interval is
// the hit (resoct_cubic_first_root). The first cell with a root wins, so the hit is the first
// crossing of the trilinear field inside the bracket, wherever in the bracket it lies.
//
// The cubic solver splits [0, smax] at the real roots of the derivative into monotone pieces and
// finds the first piece whose ends differ in sign (or that starts at an exact zero) by a
// safeguarded Illinois regula falsi. A double root at an extremum (a ray tangent to the surface)
// is reported when the extremum evaluates to exactly zero and is otherwise a miss, never NaN.
//
// Accessors: as listed in traverse.glsl.h.
#ifndef RESOCT_KERNEL_ISOSURFACE_GLSL_H
#define RESOCT_KERNEL_ISOSURFACE_GLSL_H

#include "resoct/kernel/camera_ray.glsl.h"
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/gradient.glsl.h"
#include "resoct/kernel/ray.glsl.h"

RESOCT_KERNEL_BEGIN

/// Most cells one refinement walks (a bracket spans a few cells; a bracket across a long skip
/// may span more, and is then cut here).
RESOCT_CONST(uint, RESOCT_ISO_MAX_CELLS, 4096u);
RESOCT_CONST(uint, RESOCT_CUBIC_ITERATIONS, 48u);

RESOCT_FN float resoct_cubic_eval(vec4 c, float s) {
  return c.x + s * (c.y + s * (c.z + s * c.w));
}

/// First root of g(s) = c.x + c.y s + c.z s² + c.w s³ in the monotone piece [a, b] whose end
/// values ga, gb differ in sign: Illinois regula falsi, bisection when it stalls.
RESOCT_FN float resoct_cubic_bracketed_root(vec4 c, float a, float b, float ga, float gb) {
  float lo = a;
  float hi = b;
  float glo = ga;
  float ghi = gb;
  int side = 0;
  for (uint i = 0u; i < RESOCT_CUBIC_ITERATIONS; ++i) {
    float x = (lo * ghi - hi * glo) / (ghi - glo);
    if (!(x > lo && x < hi)) x = 0.5f * (lo + hi);
    if (!(x > lo && x < hi)) break;  // the bracket is down to adjacent floats
    float gx = resoct_cubic_eval(c, x);
    if (gx == 0.0f) return x;
    if ((gx < 0.0f) == (glo < 0.0f)) {
      lo = x;
      glo = gx;
      if (side == -1) ghi = 0.5f * ghi;
      side = -1;
    } else {
      hi = x;
      ghi = gx;
      if (side == 1) glo = 0.5f * glo;
      side = 1;
    }
  }
  return abs(glo) <= abs(ghi) ? lo : hi;
}

/// First root of the cubic in [0, smax], or -1 when it has none there.
RESOCT_FN float resoct_cubic_first_root(vec4 c, float smax) {
  // Monotone pieces: split at the roots of g'(s) = c.y + 2 c.z s + 3 c.w s².
  float e0 = smax;
  float e1 = smax;
  float qa = 3.0f * c.w;
  float qb = 2.0f * c.z;
  float qc = c.y;
  float scale = max(abs(qa), max(abs(qb), abs(qc)));
  if (scale > 0.0f) {
    if (abs(qa) <= 1.0e-7f * scale) {
      if (qb != 0.0f) e0 = -qc / qb;
    } else {
      float disc = qb * qb - 4.0f * qa * qc;
      if (disc >= 0.0f) {
        // Stable quadratic roots: q = −(b + sign(b)√D)/2, roots q/a and c/q.
        float q = -0.5f * (qb + (qb >= 0.0f ? sqrt(disc) : -sqrt(disc)));
        float r0 = q / qa;
        float r1 = q != 0.0f ? qc / q : r0;
        e0 = min(r0, r1);
        e1 = max(r0, r1);
      }
    }
  }
  if (!(e0 > 0.0f && e0 < smax)) e0 = smax;
  if (!(e1 > 0.0f && e1 < smax)) e1 = smax;
  float split0 = min(e0, e1);
  float split1 = max(e0, e1);
  float a = 0.0f;
  float ga = resoct_cubic_eval(c, 0.0f);
  for (uint piece = 0u; piece < 3u; ++piece) {
    float b = piece == 0u ? split0 : (piece == 1u ? split1 : smax);
    if (ga == 0.0f) return a;
    if (b > a) {
      float gb = resoct_cubic_eval(c, b);
      if (gb == 0.0f) return b;
      if ((ga < 0.0f) != (gb < 0.0f)) return resoct_cubic_bracketed_root(c, a, b, ga, gb);
      a = b;
      ga = gb;
    }
  }
  return -1.0f;
}

/// Value of `level` at ray parameter t (position clamped into the volume), false when missing.
RESOCT_FN bool resoct_iso_value_at(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                                   RESOCT_IN(ResoctSlotInfo) s, uint level, ivec3 o_cell,
                                   vec3 o_frac, vec3 dir_vox, float t, RESOCT_OUT(float) value) {
  ivec3 cell;
  vec3 frac;
  resoct_ray_position(o_cell, o_frac, dir_vox, t, cell, frac);
  resoct_fx_clamp(p, cell, frac);
  return resoct_level_value(sp, s, level, cell, frac, value);
}

/// Ray parameter where the ray crosses the level-l voxel-centre plane `k` of axis `a`, from the
/// position (cell, frac) at t0: plane at level-0 coordinate (k + 1/2) 2^f, subtracted in
/// integers first.
RESOCT_FN float resoct_iso_plane_t(float t0, ivec3 cell, vec3 frac, vec3 dir_vox, ivec3 h, int a,
                                   int k) {
  float d = float(k * h[a] - cell[a]) + 0.5f * float(h[a]) - frac[a];
  return t0 + d / dir_vox[a];
}

/// First t in [t0, t1] where the trilinear field of `level` equals `iso` along the ray, walking
/// the level's cells in ray order; false when no cell of the bracket has a root (or its bricks
/// are missing).
RESOCT_FN bool resoct_iso_refine(RESOCT_IN(ResoctSampleParams) sp, RESOCT_IN(ResoctFxParams) p,
                                 RESOCT_IN(ResoctSlotInfo) s, uint level, float iso, ivec3 o_cell,
                                 vec3 o_frac, vec3 dir_vox, float t0, float t1,
                                 RESOCT_OUT(float) t_hit) {
  t_hit = t1;
  RESOCT_IN(ResoctLevelInfo) L = resoct_read_level(level);
  uvec3 fl = resoct_level_factor(L);
  ivec3 h = ivec3(uvec3(1u) << fl);
  ivec3 cell;
  vec3 frac;
  resoct_ray_position(o_cell, o_frac, dir_vox, t0, cell, frac);
  // Per axis: the next voxel-centre plane ahead of t0 and the parameter where it is crossed.
  ivec3 next_k = ivec3(0);
  ivec3 step_k = ivec3(0);
  vec3 t_next = vec3(RESOCT_RAY_T_INF);
  for (int a = 0; a < 3; ++a) {
    if (abs(dir_vox[a]) < RESOCT_RAY_PARALLEL_EPS) continue;
    // Level coordinate u = (cell + frac) / 2^f; centre plane k sits at u = k + 1/2.
    int whole = cell[a] >> int(fl[a]);
    float sub = (float(cell[a] - (whole << int(fl[a]))) + frac[a]) / float(h[a]);
    int k = sub >= 0.5f ? whole : whole - 1;  // plane at or below the position
    step_k[a] = dir_vox[a] > 0.0f ? 1 : -1;
    next_k[a] = dir_vox[a] > 0.0f ? k + 1 : k;
    t_next[a] = resoct_iso_plane_t(t0, cell, frac, dir_vox, h, a, next_k[a]);
  }
  float ta = t0;
  for (uint i = 0u; i < RESOCT_ISO_MAX_CELLS && ta < t1; ++i) {
    int a = t_next.x <= t_next.y ? (t_next.x <= t_next.z ? 0 : 2) : (t_next.y <= t_next.z ? 1 : 2);
    float tb = min(max(t_next[a], ta), t1);
    if (tb > ta) {
      // The cubic through four samples of the cell's interval (one call site: small GPU code).
      float hs = (tb - ta) / 3.0f;
      float g[4];
      bool ok = true;
      for (int j = 0; j < 4; ++j) {
        float v;
        ok = resoct_iso_value_at(sp, p, s, level, o_cell, o_frac, dir_vox,
                                 j == 3 ? tb : ta + float(j) * hs, v) &&
             ok;
        g[j] = v - iso;
      }
      if (ok) {
        // Newton forward differences on the nodes s = 0, 1, 2, 3, converted to powers of s.
        float d1 = g[1] - g[0];
        float d2 = g[2] - 2.0f * g[1] + g[0];
        float d3 = g[3] - 3.0f * g[2] + 3.0f * g[1] - g[0];
        vec4 c = vec4(g[0], d1 - 0.5f * d2 + d3 / 3.0f, 0.5f * d2 - 0.5f * d3, d3 / 6.0f);
        float r = resoct_cubic_first_root(c, 3.0f);
        if (r >= 0.0f) {
          t_hit = ta + r * hs;
          return true;
        }
      }
    }
    ta = max(ta, tb);
    if (t_next[a] >= RESOCT_RAY_T_INF) break;
    next_k[a] = next_k[a] + step_k[a];
    t_next[a] = resoct_iso_plane_t(t0, cell, frac, dir_vox, h, a, next_k[a]);
  }
  return false;
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_ISOSURFACE_GLSL_H
