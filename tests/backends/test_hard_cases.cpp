// The hard cases of docs/architecture.md §5 through the traversal kernel on every backend (cpu,
// and vulkan when built: tests/backends/backend_test_util.hpp). Every render asserts that the
// iteration cap was never hit (termination) and compares against a brute-force definition: the
// reference renderer, a closed form, or the background.
#include <cmath>
#include <cstdio>
#include <limits>

#include <gtest/gtest.h>

#include "backend_test_util.hpp"
#include "cpu/cpu_test_util.hpp"
#include "resoct/scene/camera.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/sources/in_memory_source.hpp"

namespace resoct::test {
namespace {

// Tolerance against the reference renderer (see test_cpu_traverse.cpp for the error budget), per
// case about three times the largest error measured over the three modes and both backends.
struct RefTolerance {
  double max_abs;
  double rmse;
};

BrickLayout bricks8() {
  BrickLayout l;
  l.brick_size = glm::uvec3(8);
  return l;
}

std::vector<TfPoint> warm_tf(double alpha = 0.15) {
  return {{0.0, {1, 1, 1, 0}}, {0.3, {1, 0.6, 0.2, alpha / 3}}, {1.0, {0.2, 0.4, 1.0, alpha}}};
}

class BackendHardCases : public BackendTest {
 protected:
  void expect_reference(const BrickSource& src, const VoxelFunction& voxels, const Scene& s,
                        const std::string& what, RefTolerance tol,
                        const ReferenceOptions& ref_options = {});
};

void BackendHardCases::expect_reference(const BrickSource& src, const VoxelFunction& voxels,
                                        const Scene& s, const std::string& what, RefTolerance tol,
                                        const ReferenceOptions& ref_options) {
  ResidentScene rs(src, {0});
  const Image ref = render_reference(s, src.hierarchy().volume(), voxels, ref_options);
  for (RenderMode m : {RenderMode::residency, RenderMode::pagetable, RenderMode::octree}) {
    FrameOptions o;
    o.mode = m;
    const Rendered r = render(rs, s, o);
    EXPECT_LT(max_diff(r.image, ref), tol.max_abs) << what << " mode " << to_string(m);
    EXPECT_LT(compare_images(r.image, ref).rmse_rgb, tol.rmse) << what << " mode " << to_string(m);
    EXPECT_EQ(r.stats.cap_hits, 0u) << what;
    EXPECT_FALSE(has_nan(r.image)) << what;
  }
}

// Orthographic rays parallel to z whose centres lie exactly on voxel, brick and octree-node
// faces, edges and corners, including the volume's lower faces (inside) and upper faces
// (outside): pixel (px, py) has its ray at x = px / 16, y = (16 − py) / 16.
TEST_P(BackendHardCases, AxisParallelRaysOnFacesEdgesCorners) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  Camera c;
  c.projection = Projection::orthographic;
  c.eye = {0.5, 0.5, 3.0};
  c.target = {0.5, 0.5, 0.0};
  c.ortho_height = 17.0 / 16.0;
  Scene s = make_scene(17, c);
  s.channels = {make_channel(0, warm_tf(), 0, 0)};
  const CameraRays rays(s.camera, s.viewport);
  ASSERT_EQ(rays.pixel_ray(16, 0).origin.x, 1.0);
  ASSERT_EQ(rays.pixel_ray(0, 16).origin.y, 0.0);
  expect_reference(src, level0_voxels(src), s, "faces", {1e-4, 4e-5});
  // The upper x face belongs to the neighbour: that column stays background.
  ResidentScene rs(src, {0});
  const Rendered r = render(rs, s);
  for (std::uint32_t y = 0; y < 17; ++y) {
    EXPECT_EQ(r.image.at(16, y), glm::vec4(0, 0, 0, 1));
  }
}

// A perspective ray along the main diagonal passes exactly through voxel, brick and node
// corners.
TEST_P(BackendHardCases, DiagonalThroughCorners) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  Camera c;
  c.eye = {-0.5, -0.5, -0.5};
  c.target = {0.5, 0.5, 0.5};
  c.up = {0.0, 1.0, 0.0};
  c.fov_deg = 30.0;
  Scene s = make_scene(9, c);
  s.channels = {make_channel(0, warm_tf(), 0, 0)};
  expect_reference(src, level0_voxels(src), s, "diagonal", {3e-4, 1e-4});
}

TEST_P(BackendHardCases, CameraInsideVolumeBrickAndOnBoundary) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  const VoxelFunction vox = level0_voxels(src);
  // Exactly on a brick/node corner at the centre, inside a brick, and on the volume's face.
  for (glm::dvec3 eye : {glm::dvec3(0.5, 0.5, 0.5), glm::dvec3(0.43, 0.51, 0.47),
                         glm::dvec3(0.5, 0.5, 0.0), glm::dvec3(0.25, 0.75, 0.5)}) {
    Camera c;
    c.eye = eye;
    c.target = eye + glm::dvec3(0.3, -0.2, 1.0);
    c.fov_deg = 70.0;
    Scene s = make_scene(20, c);
    s.channels = {make_channel(0, warm_tf(), 0, 0)};
    expect_reference(src, vox, s, "eye inside", {6e-4, 1.7e-4});
  }
}

// Segment ends exactly on faces: axis-parallel orthographic rays start at x = 2 voxels (the
// eye plane inside the volume) with a step of 4 voxels, so every sample midpoint is a multiple of
// 4 voxels and every brick face (8), octree node face (8, 16) and the volume's far face (32)
// lies exactly on a midpoint or a segment end, in exactly representable floats. The reference
// takes the same samples, so only the LUT and float rounding separate them.
TEST_P(BackendHardCases, SegmentEndsOnNodeBrickAndVolumeFaces) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  Camera c;
  c.projection = Projection::orthographic;
  c.eye = {2.0 / 32.0, 0.5, 0.5};
  c.target = {1.0, 0.5, 0.5};
  c.ortho_height = 1.0;
  Scene s = make_scene(16, c);
  s.step_scale = 4.0;
  s.channels = {make_channel(0, warm_tf(0.4), 0, 0)};
  ReferenceOptions same_samples;
  same_samples.step = 4.0;
  // Measured 4.8e-6 max, 1.4e-6 RMSE on both backends (3.0e-7 and 7.5e-8 while every sample
  // corrected its own opacity: full steps now interpolate their step level's corrected,
  // premultiplied LUT, kernel/step_lut.glsl.h, which differs from correcting the interpolated
  // entry by second-order terms inside one LUT cell; step 4 is a level exactly).
  expect_reference(src, level0_voxels(src), s, "segment ends on faces", {1.5e-5, 4.5e-6},
                   same_samples);
}

TEST_P(BackendHardCases, GrazingRaysAndMisses) {
  ProceduralSource src("procedural:constant:16x16x16", bricks8());
  ResidentScene rs(src, {0});
  // Looking away from the volume: nothing is hit.
  Camera away;
  away.eye = {2.0, 0.5, 0.5};
  away.target = {3.0, 0.5, 0.5};
  Scene s = make_scene(16, away);
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0.5}}}, 0, 0)};
  Rendered r = render(rs, s);
  EXPECT_TRUE(all_background(r.image, {0, 0, 0, 1}));
  EXPECT_EQ(r.stats.samples, 0u);
  // Rays in the plane of the upper y face (outside, half-open) and of the lower face (inside).
  Camera graze;
  graze.projection = Projection::orthographic;
  graze.eye = {0.5, 1.0, 3.0};
  graze.target = {0.5, 1.0, 0.0};
  graze.ortho_height = 1.0 / 64.0;
  s = make_scene(1, graze);
  s.viewport = {1, 1};
  s.ert_opacity = 1.0;
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0.5}}}, 0, 0)};
  r = render(rs, s);
  EXPECT_EQ(r.image.at(0, 0), glm::vec4(0, 0, 0, 1));
  EXPECT_EQ(r.stats.cap_hits, 0u);
  s.camera.eye.y = 0.0;
  s.camera.target.y = 0.0;
  r = render(rs, s);
  EXPECT_NEAR(r.image.at(0, 0).r, 1.0 - std::pow(0.5, 16.0), 1e-4);
  // Nearly parallel grazing rays along the top face from far away.
  Camera far;
  far.eye = {-5.0, 1.0 + 1e-7, 0.5};
  far.target = {1.0, 1.0, 0.5};
  s = make_scene(12, far);
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0.5}}}, 0, 0)};
  r = render(rs, s);
  EXPECT_EQ(r.stats.cap_hits, 0u);
  EXPECT_FALSE(has_nan(r.image));
}

TEST_P(BackendHardCases, ThinVolumes) {
  for (const char* spec :
       {"procedural:ramp:16x16x1", "procedural:ramp:40x40x1", "procedural:ramp:795x8x1"}) {
    ProceduralSource src(spec, bricks8());
    Camera c;
    c.eye = {0.3, 1.2, 0.9};
    c.target = {0.5, 0.0, 0.0};
    c.fov_deg = 50.0;
    Scene s = make_scene(24, c);
    s.channels = {make_channel(0, {{0.0, {1, 0.5, 0, 0.2}}, {1.0, {0, 0.5, 1, 0.9}}}, 0, 0)};
    expect_reference(src, level0_voxels(src), s, spec, {2.5e-3, 3.5e-4});
  }
}

TEST_P(BackendHardCases, AnisotropicSpacing) {
  VolumeDesc v;
  v.extent = {16, 16, 8};
  v.spacing = {1.0, 1.0, 20.0};
  v.type = VoxelType::f32;
  std::vector<float> values(16 * 16 * 8);
  std::vector<double> as_double(values.size());
  for (std::size_t z = 0, i = 0; z < 8; ++z) {
    for (std::size_t y = 0; y < 16; ++y) {
      for (std::size_t x = 0; x < 16; ++x, ++i) {
        values[i] = float((double(x) + 0.5) / 16.0 * 0.5 + (double(z) + 0.5) / 8.0 * 0.5);
        as_double[i] = values[i];
      }
    }
  }
  InMemorySource src(DenseVolume::from_values(v, values), BrickLayout{glm::uvec3(4), 1});
  for (glm::dvec3 eye : {glm::dvec3(1.6, 1.1, 0.02), glm::dvec3(0.3, 0.4, 2.0)}) {
    Camera c;
    c.eye = eye;
    c.target = {0.5, 0.5, 0.5};
    Scene s = make_scene(20, c);
    s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}, {1.0, {1, 0.5, 0.2, 0.2}}}, 0, 0)};
    expect_reference(src, dense_voxels(v.extent, {as_double}), s, "anisotropic", {3e-3, 1.5e-4});
  }
}

// An axis of 2^20 voxels: ortho rays through voxel centres near the far end sample the ramp
// (x + 0.5) / W there exactly (a global float position would be off by up to 1/8 voxel). Only
// the last level-0 bricks are resident; an opaque identity TF shows the first sample's value.
TEST_P(BackendHardCases, HugeAxisSamplesExactlyNearTheFarEnd) {
  constexpr std::uint64_t W = std::uint64_t(1) << 20;
  BrickLayout layout;
  layout.brick_size = glm::uvec3(64, 4, 4);
  ProceduralSource src("procedural:ramp:1048576x2x2", layout);
  const std::uint32_t last_brick = std::uint32_t(W / 64 - 1);
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(1024, 8, 8);
  ro.metadata = false;
  ro.level_resident = [](std::uint32_t l) { return l == 0; };
  ro.brick_resident = [&](std::uint32_t, glm::uvec3 b) { return b.x + 1 >= last_brick; };
  ResidentScene rs(src, {0}, ro);
  // Box units: x in [0, 1), one voxel = 2^-20. 16 columns at the centres of the last 16 voxels.
  const double vox = 1.0 / double(W);
  Camera c;
  c.projection = Projection::orthographic;
  c.eye = {1.0 - 8.0 * vox, 1.0 * vox, 0.5};
  c.target = {1.0 - 8.0 * vox, 1.0 * vox, 0.0};
  c.ortho_height = 1.0 * vox;
  Scene s = make_scene(1, c);
  s.viewport = {16, 1};
  s.ert_opacity = 1.0;
  s.lod_error_px = 1e-3;
  s.channels = {make_channel(0, {{0.0, {0, 0, 0, 1}}, {1.0, {1, 1, 1, 1}}}, 0, 0)};
  const Rendered r = render(rs, s);
  EXPECT_EQ(r.stats.cap_hits, 0u);
  for (std::uint32_t x = 0; x < 16; ++x) {
    const double expected = (double(W - 16 + x) + 0.5) / double(W);
    // f32 data and colours near 1 resolve 2^-24, i.e. 1/16 voxel here; allow 1/4 voxel.
    EXPECT_NEAR(r.image.at(x, 0).r, expected, 0.25 / double(W)) << "column " << x;
  }
}

TEST_P(BackendHardCases, StepRangeConvergesWithoutCapHits) {
  ProceduralSource src("procedural:constant:16x16x16", bricks8());
  ResidentScene rs(src, {0});
  const double a = 0.1;
  for (double step : {1e-3, 0.01, 0.5, 2.0, 8.0}) {
    Camera c;
    c.projection = Projection::orthographic;
    c.eye = {0.5, 0.5, 2.0};
    c.target = {0.5, 0.5, 0.0};
    c.ortho_height = 0.5;
    Scene s = make_scene(2, c);
    s.step_scale = step;
    s.ert_opacity = 1.0;
    s.channels = {make_channel(0, {{0.0, {1, 1, 1, a}}}, 0, 0)};
    for (RenderMode m : {RenderMode::residency, RenderMode::pagetable, RenderMode::octree}) {
      FrameOptions o;
      o.mode = m;
      const Rendered r = render(rs, s, o);
      // 16 000 samples per ray at step 1e-3 exceed the loop guard of a driver that has one
      // (lavapipe: 65535 back-edges per invocation). Those rays must all be reported as stopped
      // by the cap, none rendered short silently; the other steps must work everywhere.
      if (step < 0.01 && loop_limit() != 0 && r.stats.cap_hits != 0) {
        EXPECT_EQ(r.stats.cap_hits, r.stats.rays) << "step " << step;
        std::printf(
            "[ %s ] step %g %s: beyond the driver's loop limit of %u, all rays "
            "reported as capped\n",
            GetParam().c_str(), step, to_string(m), loop_limit());
        continue;
      }
      EXPECT_EQ(r.stats.cap_hits, 0u);
      for (const auto& p : r.image.pixels()) {
        EXPECT_NEAR(p.r, 1.0 - std::pow(1.0 - a, 16.0), 1e-3) << "step " << step;
      }
    }
  }
}

TEST_P(BackendHardCases, IterationCapStopsAndCounts) {
  ProceduralSource src("procedural:constant:16x16x16", bricks8());
  ResidentScene rs(src, {0});
  Scene s = make_scene(4);
  s.step_scale = 0.01;
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0.001}}}, 0, 0)};
  FrameOptions o;
  o.max_iterations = 10;
  const Rendered r = render(rs, s, o);
  EXPECT_EQ(r.stats.cap_hits, r.stats.rays);
  EXPECT_EQ(r.stats.iterations, 10u * r.stats.rays);
}

TEST_P(BackendHardCases, TransparentAndOpaqueTransferFunctions) {
  ProceduralSource src("procedural:sphere:24x24x24", bricks8());
  ResidentScene rs(src, {0});
  Camera c;
  c.eye = {0.5, 0.5, 2.5};
  c.target = {0.5, 0.5, 0.5};
  Scene s = make_scene(24, c);
  s.background = {0.1, 0.2, 0.3, 1.0};
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}}, 0, 0)};
  for (RenderMode m : {RenderMode::residency, RenderMode::pagetable, RenderMode::octree}) {
    FrameOptions o;
    o.mode = m;
    const Rendered r = render(rs, s, o);
    EXPECT_TRUE(all_background(r.image, {0.1f, 0.2f, 0.3f, 1.0f}));
    EXPECT_EQ(r.stats.samples, 0u);
    EXPECT_TRUE(r.bricks.empty());
  }
  // Opaque everywhere: every ray that enters the volume shows the TF colour.
  s.channels = {make_channel(0, {{0.0, {0.9, 0.1, 0.3, 1}}}, 0, 0)};
  const Rendered r = render(rs, s);
  const Rendered ref{render_reference(s, src.hierarchy().volume(), level0_voxels(src)), {}, {}, {}};
  EXPECT_LT(max_diff(r.image, ref.image), 1e-5);
  EXPECT_EQ(r.image.at(12, 12), glm::vec4(0.9f, 0.1f, 0.3f, 1.0f));
}

TEST_P(BackendHardCases, NanAndInfVoxels) {
  VolumeDesc v;
  v.extent = {16, 16, 16};
  v.type = VoxelType::f32;
  std::vector<float> values(16 * 16 * 16);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::size_t k = (i * 2654435761u) % 97u;
    values[i] = k == 0   ? std::numeric_limits<float>::quiet_NaN()
                : k == 1 ? std::numeric_limits<float>::infinity()
                : k == 2 ? -std::numeric_limits<float>::infinity()
                         : float(k) / 97.0f;
  }
  InMemorySource src(DenseVolume::from_values(v, values), bricks8());
  ResidentScene rs(src, {0});
  Scene s = make_scene(24, Camera{});
  s.channels = {make_channel(0, warm_tf(0.3), 0, 15)};
  for (RenderMode m : {RenderMode::residency, RenderMode::pagetable, RenderMode::octree}) {
    FrameOptions o;
    o.mode = m;
    const Rendered r = render(rs, s, o);
    EXPECT_FALSE(has_nan(r.image)) << to_string(m);
    EXPECT_EQ(r.stats.cap_hits, 0u);
    EXPECT_GT(r.stats.samples, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(HardCases, BackendHardCases, ::testing::ValuesIn(test_backends()),
                         backend_param_name);

}  // namespace
}  // namespace resoct::test
