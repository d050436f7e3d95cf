// kernel/step.glsl.h compiled as C++: Eq. 8.2-8.3 step size with zero guards, progress of t,
// and the per-sample LOD level against hand calculations.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace resoct::kernel {
// Level sizes of the test hierarchy: log2 of the largest voxel dimension per level, box units.
inline std::array<float, 32> g_level_size_log2{};
inline float resoct_read_level_size_log2(std::uint32_t level) {
  return g_level_size_log2[level];
}
}  // namespace resoct::kernel

#include "resoct/scene/camera.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/kernel/step.glsl.h"

namespace {

using namespace resoct::kernel;

// Isotropic 256^3, every level doubling the voxel: size(l) = 2^l / 256.
void set_isotropic_levels() {
  for (int l = 0; l < 32; ++l) g_level_size_log2[std::size_t(l)] = float(l - 8);
}

TEST(KernelStep, MatchesEq82And83ForKnownInputs) {
  // Volume 256 x 128 x 64 voxels, spacing 1: box extent (1, 0.5, 0.25), voxel 1/256 per axis.
  const vec3 h(1.0f / 256.0f);
  const vec3 d = glm::normalize(vec3(1.0f, 2.0f, 2.0f));  // (1/3, 2/3, 2/3)
  // dt_i = h_i / |d_i|: (3/256, 1.5/256, 1.5/256); min = 1.5/256.
  EXPECT_NEAR(resoct_step_size(d, h, 1.0f, 0.0f), 1.5f / 256.0f, 1e-8f);
  EXPECT_NEAR(resoct_step_size(d, h, 0.25f, 0.0f), 0.375f / 256.0f, 1e-8f);
  // Axis-aligned: exactly one voxel.
  EXPECT_FLOAT_EQ(resoct_step_size(vec3(0.0f, -1.0f, 0.0f), h, 1.0f, 0.0f), 1.0f / 256.0f);
}

TEST(KernelStep, ZeroComponentsAreGuarded) {
  const vec3 h(0.01f, 0.02f, 0.04f);
  const float dt = resoct_step_size(vec3(0.0f, -0.0f, 1.0f), h, 1.0f, 0.0f);
  EXPECT_FALSE(std::isnan(dt));
  EXPECT_FLOAT_EQ(dt, 0.04f);
  // All-zero direction: the smallest voxel dimension, never inf or NaN.
  const float z = resoct_step_size(vec3(0.0f), h, 2.0f, 0.0f);
  EXPECT_FLOAT_EQ(z, 0.02f);
  // The floor applies.
  EXPECT_FLOAT_EQ(resoct_step_size(vec3(1.0f, 0.0f, 0.0f), h, 1e-6f, 1e-5f), 1e-5f);
}

TEST(KernelStep, AnisotropicSpacing1To1To20) {
  // 64 x 64 x 8 voxels with spacing (1, 1, 20): physical 64 x 64 x 160, box (0.4, 0.4, 1),
  // voxel size (1/160, 1/160, 20/160).
  const vec3 h(1.0f / 160.0f, 1.0f / 160.0f, 20.0f / 160.0f);
  // Along z the step is one (thick) z voxel; along x one thin voxel.
  EXPECT_FLOAT_EQ(resoct_step_size(vec3(0.0f, 0.0f, 1.0f), h, 1.0f, 0.0f), 20.0f / 160.0f);
  EXPECT_FLOAT_EQ(resoct_step_size(vec3(1.0f, 0.0f, 0.0f), h, 1.0f, 0.0f), 1.0f / 160.0f);
  // Diagonal in x-z: dt_x = (1/160)/s, dt_z = (20/160)/s with s = 1/sqrt(2): x limits.
  const float s = 1.0f / std::sqrt(2.0f);
  EXPECT_NEAR(resoct_step_size(vec3(s, 0.0f, s), h, 1.0f, 0.0f), (1.0f / 160.0f) / s, 1e-7f);
}

TEST(KernelStep, AdvanceAlwaysMakesProgress) {
  for (float t : {0.0f, 1e-30f, 1.0f, 1000.0f, 1e7f, 3e8f}) {
    const float next = resoct_advance_t(t, 1e-12f);
    EXPECT_GT(next, t) << t;
  }
  EXPECT_FLOAT_EQ(resoct_advance_t(1.0f, 0.5f), 1.5f);
  // Counting iterations over a span with a tiny step terminates by the guaranteed ulp advance.
  float t = 16777216.0f;  // 2^24: t + 0.1 rounds back to t
  int n = 0;
  while (t < 16777216.0f + 64.0f && n < 1000) {
    t = resoct_advance_t(t, 0.1f);
    ++n;
  }
  EXPECT_LT(n, 1000);
}

TEST(KernelLod, HandCalculationPerspective) {
  set_isotropic_levels();
  // fov 90 degrees, 256 pixel rows: a pixel is 2 tan(45°) / 256 = 1/128 per unit depth.
  const float slope = 2.0f * std::tan(glm::radians(45.0f)) / 256.0f;
  // At depth 1 a pixel is 1/128 = two level-0 voxels: level 1 (voxel 2/256) fits, level 2 not.
  const float budget = resoct_lod_budget_log2(0.0f, slope, 1.0f, 1.0f);
  EXPECT_NEAR(budget, -7.0f, 1e-5f);
  EXPECT_EQ(resoct_lod_level(budget, 9u), 1u);
  // Twice the error threshold allows one level coarser; at depth 0.25 the level-0 voxel is
  // half a pixel wide, so level 0.
  EXPECT_EQ(resoct_lod_level(resoct_lod_budget_log2(0.0f, slope, 1.0f, 2.0f), 9u), 2u);
  EXPECT_EQ(resoct_lod_level(resoct_lod_budget_log2(0.0f, slope, 0.25f, 1.0f), 9u), 0u);
  // Far away: capped at the last level.
  EXPECT_EQ(resoct_lod_level(resoct_lod_budget_log2(0.0f, slope, 1e6f, 1.0f), 9u), 8u);
}

TEST(KernelLod, CameraAndHierarchyTablesGiveTheHandCalculatedLevel) {
  // 256^3 voxels, 32^3 bricks: levels 0..3 with voxels 1, 2, 4, 8 level-0 voxels wide.
  resoct::VolumeDesc v;
  v.extent = {256, 256, 256};
  const resoct::BrickHierarchy hier(v, resoct::BrickLayout{});
  ASSERT_EQ(hier.level_count(), 4u);
  const std::vector<float> table = resoct::level_size_log2_table(hier);
  std::copy(table.begin(), table.end(), g_level_size_log2.begin());
  resoct::Camera cam;
  cam.eye = {0.5, 0.5, 3.0};
  cam.target = {0.5, 0.5, 0.5};
  cam.fov_deg = 90.0;
  const resoct::CameraRays rays(cam, resoct::Viewport{256, 256});
  // Centre ray; the sample at t = 1.5 has depth 1.5 and a footprint of 1.5/128 = 3 voxels:
  // level 1 (2 voxels) fits, level 2 (4 voxels) does not.
  const resoct::Ray r = rays.ray(128.0, 128.0);
  const float depth = float(1.5 * glm::dot(r.dir, rays.forward()));
  const float budget = resoct_lod_budget_log2(float(rays.footprint_base()),
                                              float(rays.footprint_slope()), depth, 1.0f);
  EXPECT_EQ(resoct_lod_level(budget, hier.level_count()), 1u);
  // At depth 2.5 (footprint 5 voxels) level 2; with lod_error_px = 2 at depth 1.5, level 2.
  EXPECT_EQ(
      resoct_lod_level(resoct_lod_budget_log2(0.0f, float(rays.footprint_slope()), 2.5f, 1.0f),
                       hier.level_count()),
      2u);
  EXPECT_EQ(
      resoct_lod_level(resoct_lod_budget_log2(0.0f, float(rays.footprint_slope()), 1.5f, 2.0f),
                       hier.level_count()),
      2u);
}

TEST(KernelLod, OrthographicIsIndependentOfDepth) {
  set_isotropic_levels();
  // View height 1 over 64 rows: footprint 1/64 = 4 level-0 voxels: level 2 everywhere.
  for (float z : {0.0f, 0.5f, 10.0f}) {
    EXPECT_EQ(resoct_lod_level(resoct_lod_budget_log2(1.0f / 64.0f, 0.0f, z, 1.0f), 9u), 2u);
  }
}

TEST(KernelLod, MonotoneInDistanceAndClamped) {
  set_isotropic_levels();
  const float slope = 2.0f * std::tan(glm::radians(20.0f)) / 512.0f;
  std::uint32_t previous = 0;
  for (float z = 1e-3f; z < 1e4f; z *= 1.01f) {
    const std::uint32_t l = resoct_lod_level(resoct_lod_budget_log2(0.0f, slope, z, 1.0f), 9u);
    EXPECT_GE(l, previous);
    previous = l;
    const std::uint32_t c = resoct_channel_level(l, 2u, 5u);
    EXPECT_GE(c, 2u);
    EXPECT_LE(c, 5u);
    EXPECT_EQ(c, std::min(std::max(l, 2u), 5u));
  }
  EXPECT_EQ(previous, 8u);
  // A depth of 0 (camera on the sample) has zero footprint: the finest level, no NaN from log2.
  EXPECT_EQ(resoct_lod_level(resoct_lod_budget_log2(0.0f, slope, 0.0f, 1.0f), 9u), 0u);
}

TEST(KernelLod, AnisotropicLevelsUseLargestVoxelDimension) {
  // 1:1:20 slab whose first four levels halve only x and y (1024 x 1024 x 40 with 32^3 bricks):
  // largest dimension of level l is max(2^l, 20) voxels of size h.
  const float h = 1.0f / 1024.0f;
  for (int l = 0; l < 32; ++l) {
    const float xy = std::ldexp(h, l);
    const float z = l < 5 ? 20.0f * h : std::ldexp(20.0f * h, l - 4);
    g_level_size_log2[std::size_t(l)] = std::log2(std::max(xy, z));
  }
  // A footprint of 19 h fits no level (level 0 is already 20 h across in z): finest.
  EXPECT_EQ(resoct_lod_level(std::log2(19.0f * h), 10u), 0u);
  // 20 h: levels 0..4 all have largest dimension 20 h; the coarsest of them, 4, is chosen.
  EXPECT_EQ(resoct_lod_level(std::log2(20.5f * h), 10u), 4u);
  // 33 h: level 5 is (32, 32, 40) h: too large in z; still 4.
  EXPECT_EQ(resoct_lod_level(std::log2(33.0f * h), 10u), 4u);
  EXPECT_EQ(resoct_lod_level(std::log2(40.0f * h), 10u), 5u);
}

}  // namespace
