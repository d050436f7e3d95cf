// kernel/ray.glsl.h compiled as C++: slab test against brute-force expectations, half-open
// faces, axis-parallel and grazing rays, ±0 directions, and node-local precision at 2^20 voxels.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "resoct/kernel/ray.glsl.h"

namespace {

using namespace resoct::kernel;

bool inside_half_open(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
  return p.x >= lo.x && p.x < hi.x && p.y >= lo.y && p.y < hi.y && p.z >= lo.z && p.z < hi.z;
}

void expect_no_nan(vec2 t) {
  EXPECT_FALSE(std::isnan(t.x));
  EXPECT_FALSE(std::isnan(t.y));
}

TEST(KernelRay, AxisParallelThroughUnitBox) {
  const vec2 t =
      resoct_ray_box(vec3(-1.0f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f));
  expect_no_nan(t);
  EXPECT_FLOAT_EQ(t.x, 1.0f);
  EXPECT_FLOAT_EQ(t.y, 2.0f);
  // Negative direction, and a negative-zero component that must act like +0.
  const vec2 u =
      resoct_ray_box(vec3(0.5f, 2.0f, 0.25f), vec3(-0.0f, -1.0f, -0.0f), vec3(0.0f), vec3(1.0f));
  expect_no_nan(u);
  EXPECT_FLOAT_EQ(u.x, 1.0f);
  EXPECT_FLOAT_EQ(u.y, 2.0f);
}

TEST(KernelRay, RayOnLowerFaceIsInsideUpperFaceIsOutside) {
  // y = 0 (lower face): inside; y = 1 (upper face): belongs to the neighbour.
  const vec3 dir(1.0f, 0.0f, 0.0f);
  const vec2 lower = resoct_ray_box(vec3(-1.0f, 0.0f, 0.5f), dir, vec3(0.0f), vec3(1.0f));
  expect_no_nan(lower);
  EXPECT_TRUE(resoct_ray_hits(lower, 0.0f));
  EXPECT_FLOAT_EQ(lower.x, 1.0f);
  EXPECT_FLOAT_EQ(lower.y, 2.0f);
  const vec2 upper = resoct_ray_box(vec3(-1.0f, 1.0f, 0.5f), dir, vec3(0.0f), vec3(1.0f));
  expect_no_nan(upper);
  EXPECT_FALSE(resoct_ray_hits(upper, 0.0f));
}

TEST(KernelRay, RayOnEdgesAndCorners) {
  const vec3 dir(0.0f, 0.0f, 1.0f);
  // Along the lower-lower edge x = 0, y = 0: inside.
  const vec2 e00 = resoct_ray_box(vec3(0.0f, 0.0f, -2.0f), dir, vec3(0.0f), vec3(1.0f));
  expect_no_nan(e00);
  EXPECT_TRUE(resoct_ray_hits(e00, 0.0f));
  EXPECT_FLOAT_EQ(e00.x, 2.0f);
  EXPECT_FLOAT_EQ(e00.y, 3.0f);
  // Any edge touching an upper face: outside.
  for (const vec3 o : {vec3(1.0f, 0.0f, -2.0f), vec3(0.0f, 1.0f, -2.0f), vec3(1.0f, 1.0f, -2.0f)}) {
    const vec2 t = resoct_ray_box(o, dir, vec3(0.0f), vec3(1.0f));
    expect_no_nan(t);
    EXPECT_FALSE(resoct_ray_hits(t, 0.0f));
  }
  // The body diagonal from corner to corner is inside for its whole length.
  const float s = 1.0f / std::sqrt(3.0f);
  const vec2 diag = resoct_ray_box(vec3(0.0f), vec3(s), vec3(0.0f), vec3(1.0f));
  expect_no_nan(diag);
  EXPECT_FLOAT_EQ(diag.x, 0.0f);
  EXPECT_NEAR(diag.y, std::sqrt(3.0f), 1e-6f);
  // A ray that only touches the corner (1, 1, 1) from outside: empty interval.
  const vec2 touch =
      resoct_ray_box(vec3(2.0f, 2.0f, 0.0f), vec3(-s, -s, s), vec3(0.0f), vec3(1.0f));
  expect_no_nan(touch);
  EXPECT_FALSE(touch.x < touch.y && touch.y - touch.x > 1e-5f);
}

TEST(KernelRay, OriginInsideAndMisses) {
  const vec2 t =
      resoct_ray_box(vec3(0.25f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f));
  EXPECT_FLOAT_EQ(t.x, -0.25f);
  EXPECT_FLOAT_EQ(t.y, 0.75f);
  EXPECT_TRUE(resoct_ray_hits(t, 0.0f));
  // Pointing away: the interval lies behind the origin.
  const vec2 away =
      resoct_ray_box(vec3(2.0f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f));
  EXPECT_FALSE(resoct_ray_hits(away, 0.0f));
  // Parallel outside the slab.
  const vec2 par =
      resoct_ray_box(vec3(-1.0f, 1.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f));
  expect_no_nan(par);
  EXPECT_FALSE(resoct_ray_hits(par, 0.0f));
}

TEST(KernelRay, DegenerateDirectionsNeverNaN) {
  // Zero direction: inside everywhere or nowhere, never NaN.
  const vec2 in = resoct_ray_box(vec3(0.5f), vec3(0.0f), vec3(0.0f), vec3(1.0f));
  expect_no_nan(in);
  EXPECT_TRUE(resoct_ray_hits(in, 0.0f));
  const vec2 out = resoct_ray_box(vec3(1.0f, 0.5f, 0.5f), vec3(-0.0f), vec3(0.0f), vec3(1.0f));
  expect_no_nan(out);
  EXPECT_FALSE(resoct_ray_hits(out, 0.0f));
  // Denormal components and origins exactly on slab planes.
  const float tiny = std::numeric_limits<float>::denorm_min();
  const vec2 d =
      resoct_ray_box(vec3(0.0f, 1.0f, 0.0f), vec3(1.0f, tiny, -tiny), vec3(0.0f), vec3(1.0f));
  expect_no_nan(d);
  EXPECT_FALSE(resoct_ray_hits(d, 0.0f));
}

TEST(KernelRay, ReciprocalMarksParallelAxesWithZero) {
  // 0 stands for "parallel": zero, negative zero, denormals and anything below the threshold.
  const float tiny = std::numeric_limits<float>::denorm_min();
  EXPECT_EQ(resoct_ray_inverse1(0.0f), 0.0f);
  EXPECT_EQ(resoct_ray_inverse1(-0.0f), 0.0f);
  EXPECT_EQ(resoct_ray_inverse1(tiny), 0.0f);
  EXPECT_EQ(resoct_ray_inverse1(-0.5f * RESOCT_RAY_PARALLEL_EPS), 0.0f);
  // Anything else is the correctly rounded reciprocal, finite and never 0.
  EXPECT_EQ(resoct_ray_inverse1(4.0f), 0.25f);
  EXPECT_EQ(resoct_ray_inverse1(-3.0f), 1.0f / -3.0f);
  const float r = resoct_ray_inverse1(RESOCT_RAY_PARALLEL_EPS);
  EXPECT_TRUE(std::isfinite(r));
  EXPECT_GT(r, 0.0f);
  // A parallel axis decides by position alone, through the reciprocal form as well.
  const vec3 inv = resoct_ray_inverse(vec3(1.0f, -0.0f, tiny));
  EXPECT_TRUE(resoct_ray_hits(
      resoct_ray_box_inv(vec3(-1.0f, 0.5f, 0.0f), inv, vec3(0.0f), vec3(1.0f)), 0.0f));
  EXPECT_FALSE(resoct_ray_hits(
      resoct_ray_box_inv(vec3(-1.0f, 1.0f, 0.5f), inv, vec3(0.0f), vec3(1.0f)), 0.0f));
}

TEST(KernelRay, GrazingRaysMatchBruteForceMarching) {
  // Random rays, many of them nearly parallel to a face, compared with dense point sampling of
  // the half-open box in double.
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  std::uniform_int_distribution<int> axis(0, 2);
  const glm::dvec3 lo(0.0), hi(1.0);
  for (int i = 0; i < 300; ++i) {
    glm::dvec3 o(u(rng), u(rng), u(rng));
    glm::dvec3 d = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)) - glm::dvec3(0.5));
    if (i % 3 == 0) d[axis(rng)] = 1e-4 * (d.x > 0 ? 1 : -1);  // grazing
    if (i % 5 == 0) d[axis(rng)] = 0.0;                        // parallel
    if (i % 7 == 0) o[axis(rng)] = (i % 2 == 0) ? 0.0 : 1.0;   // on a face plane
    d = glm::normalize(d);
    const vec2 t = resoct_ray_box(vec3(o), vec3(d), vec3(lo), vec3(hi));
    expect_no_nan(t);
    // Brute force: which parameters in [-4, 4] lie inside?
    double first = 1e30, last = -1e30;
    const int n = 80000;
    for (int k = 0; k <= n; ++k) {
      const double s = -4.0 + 8.0 * k / n;
      if (inside_half_open(o + s * d, lo, hi)) {
        first = std::min(first, s);
        last = std::max(last, s);
      }
    }
    const double cell = 8.0 / n;
    if (first > last) {
      EXPECT_FALSE(t.x < t.y && t.y - t.x > 2 * cell) << "ray " << i;
    } else {
      EXPECT_NEAR(t.x, first, 2 * cell + 1e-5) << "ray " << i;
      EXPECT_NEAR(t.y, last, 2 * cell + 1e-5) << "ray " << i;
    }
  }
}

TEST(KernelRay, NodeLocalCoordinatesKeepPrecisionAt2Pow20) {
  // A sample 0.3 voxels into voxel 1048001, in a 16-voxel node starting at 1048000 (x ~ 2^20).
  ivec3 cell(1048000, 5, 9);
  vec3 frac(1.3f, 0.5f, 0.5f);
  resoct_split_normalize(cell, frac);
  EXPECT_EQ(cell.x, 1048001);
  EXPECT_NEAR(frac.x, 0.3f, 1e-6f);
  const ivec3 node_lo(1048000, 0, 0);
  const vec3 rel = resoct_relative_origin(cell, frac, node_lo);
  EXPECT_NEAR(rel.x, 1.3f, 1e-6f);
  const vec2 t =
      resoct_ray_node_local(rel, resoct_ray_inverse(vec3(1.0f, 0.0f, 0.0f)), vec3(16.0f));
  EXPECT_NEAR(t.y, 14.7f, 1e-5f);  // distance to the node's upper face, to float precision
  // The same in global normalized floats carries an error of a sizeable fraction of a voxel
  // (floats near 1 are 2^-24 apart, 1/16 voxel at 2^20 voxels).
  const float extent = 1048576.0f;
  const float p = float((1048001.3) / 1048576.0);
  const float node_hi = float((1048000.0 + 16.0) / 1048576.0);
  const float global_exit_voxels = (node_hi - p) * extent;
  EXPECT_GT(std::abs(global_exit_voxels - 14.7f), 0.01f);
}

}  // namespace
