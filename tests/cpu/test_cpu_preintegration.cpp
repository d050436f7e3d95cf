// Pre-integrated transfer functions in the CPU kernel (docs/rendering.md "Pre-integration"):
// against the dense double-precision reference renderer (tests/support), which point-samples
// the exact transfer function at 1/64 reference step without early termination.
#include <limits>
#include <string>
#include <vector>

#include "cpu_test_util.hpp"
#include "support/function_source.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

// A narrow, nearly opaque band of values: the sharp transfer function pre-integration is for.
std::vector<TfPoint> sharp_tf() {
  return {{0.0, {0, 0, 0, 0}},
          {0.55, {1.0, 0.4, 0.1, 0.0}},
          {0.6, {1.0, 0.9, 0.3, 0.8}},
          {0.65, {0.2, 0.4, 1.0, 0.0}},
          {1.0, {0, 0, 0, 0}}};
}

struct Errors {
  double point;
  double preint;
};

// RMSE (RGB) against `ref` without and with pre-integration at step scale `step`.
Errors rmse_at(const ResidentScene& rs, Scene scene, double step, const Image& ref,
               RenderMode mode = RenderMode::residency) {
  FrameOptions o;
  o.mode = mode;
  scene.step_scale = step;
  scene.preintegration = false;
  const double point = compare_images(render_cpu(rs, scene, o).image, ref).rmse_rgb;
  scene.preintegration = true;
  const double pre = compare_images(render_cpu(rs, scene, o).image, ref).rmse_rgb;
  return {point, pre};
}

// A ball whose value falls linearly from 1 at the centre to 0 at radius 16 voxels (f32 32³):
// along a ray the value is smooth, and the sharp TF band is a shell about 1.6 voxels thick.
FunctionSource ball_source() {
  VolumeDesc v;
  v.extent = {32, 32, 32};
  v.type = VoxelType::f32;
  v.ranges = {ValueRange{0.0, 1.0}};
  return FunctionSource(v, bricks8(), [](std::uint32_t, const glm::u64vec3& p) {
    const glm::dvec3 q = glm::dvec3(p) + 0.5;
    return std::max(0.0, 1.0 - glm::length(q - glm::dvec3(16.0)) / 16.0);
  });
}

Scene ball_scene() {
  Scene scene = make_scene(48, oblique_camera());
  scene.ert_opacity = 1.0;
  scene.channels = {make_channel(0, sharp_tf(), 0, 0)};
  return scene;
}

Image ball_reference(const FunctionSource& src, const Scene& scene) {
  ReferenceOptions ro;
  ro.step = 1.0 / 64.0;  // the sharp band needs a finer oracle than the usual 1/16
  ro.early_termination = false;
  return render_reference(
      scene, src.hierarchy().volume(),
      [&src](std::uint32_t c, const glm::i64vec3& p) { return src.voxel(0, c, p); }, ro);
}

// Measured (RMSE point → pre-integrated): step 0.25 0.0019 → 0.0004, 1: 0.025 → 0.004,
// 2: 0.066 → 0.012, 4: 0.10 → 0.042.
TEST(CpuPreintegration, SharpTfAtCoarseStepsIsFarCloserToTheReference) {
  const FunctionSource src = ball_source();
  ResidentScene rs(src, {0});
  const Scene scene = ball_scene();
  const Image ref = ball_reference(src, scene);
  // Page-table mode skips only empty bricks, residency mode also nodes the TF hides (which ends
  // runs earlier): both gain.
  for (RenderMode mode : {RenderMode::residency, RenderMode::pagetable}) {
    for (double step : {1.0, 2.0, 4.0}) {
      const Errors e = rmse_at(rs, scene, step, ref, mode);
      EXPECT_LT(e.preint, 0.5 * e.point) << "step " << step << " mode " << int(mode);
    }
  }
  // Fine steps: both converge, pre-integration no worse.
  const Errors fine = rmse_at(rs, scene, 0.25, ref);
  EXPECT_LT(fine.preint, 1e-3);
  EXPECT_LT(fine.preint, fine.point + 2e-4);
}

// The tubes of the benchmarks with the sharp band: sharp walls in the data limit what a linear
// value model between samples can do, but coarse steps still gain. A single step scale is an
// aliasing lottery here (at step 2 the ratio pre-integrated / point ranges 0.65-0.93 between step
// scales 1.8 and 2.2, and rounding the step to its level moves it), so each group averages five
// step scales around 1 and 2. Measured mean RMSE point → pre-integrated: ~1: 0.0185 → 0.0097,
// ~2: 0.0180 → 0.0130 (0.0192 → 0.0130 without step levels).
TEST(CpuPreintegration, TubesWithSharpTfGainAtCoarseSteps) {
  ProceduralSource src("procedural:tubes:32x32x32:1", bricks8());
  ResidentScene rs(src, {0});
  Scene scene = make_scene(48, oblique_camera());
  scene.ert_opacity = 1.0;
  scene.channels = {make_channel(0, sharp_tf())};
  ReferenceOptions ro;
  ro.step = 1.0 / 64.0;
  ro.early_termination = false;
  const Image ref = render_reference(scene, src.hierarchy().volume(), level0_voxels(src), ro);
  for (const double centre : {1.0, 2.0}) {
    double point = 0.0, pre = 0.0;
    for (const double f : {0.9, 0.95, 1.0, 1.05, 1.1}) {
      const Errors e = rmse_at(rs, scene, centre * f, ref);
      point += e.point / 5.0;
      pre += e.preint / 5.0;
    }
    EXPECT_LT(pre, (centre == 1.0 ? 0.6 : 0.8) * point) << "steps around " << centre;
  }
}

// Shading multiplies the pre-integrated colour: with ambient 1 and no diffuse or specular term
// Blinn-Phong is the identity, so the shaded kernel (effect path) must give the plain
// pre-integrated image.
TEST(CpuPreintegration, IdentityShadingGivesThePlainPreintegratedImage) {
  const FunctionSource src = ball_source();
  ResidentScene rs(src, {0});
  Scene scene = ball_scene();
  scene.step_scale = 2.0;
  scene.preintegration = true;
  const Image plain = render_cpu(rs, scene).image;
  scene.effects = {Effect::shading};
  scene.light.ambient = 1.0;
  scene.light.diffuse = 0.0;
  scene.light.specular = 0.0;
  const Rendered shaded = render_cpu(rs, scene);
  EXPECT_GT(shaded.stats.gradient_evals, 0u);
  EXPECT_LT(max_diff(shaded.image, plain), 1e-5);
  // And it differs from the point-sampled shaded image (the switch reached the effect path).
  scene.preintegration = false;
  EXPECT_GT(max_diff(render_cpu(rs, scene).image, plain), 1e-2);
}

// MIP and isosurfaces ignore pre-integration.
TEST(CpuPreintegration, ProjectionAndIsoChannelsIgnoreIt) {
  const FunctionSource src = ball_source();
  ResidentScene rs(src, {0});
  Scene scene = ball_scene();
  scene.step_scale = 2.0;
  for (ChannelMode mode : {ChannelMode::mip, ChannelMode::iso}) {
    scene.channels[0].mode = mode;
    scene.channels[0].isovalues =
        mode == ChannelMode::iso ? std::vector<double>{0.6} : std::vector<double>{};
    scene.preintegration = false;
    const Image off = render_cpu(rs, scene).image;
    scene.preintegration = true;
    EXPECT_EQ(max_diff(render_cpu(rs, scene).image, off), 0.0) << int(mode);
  }
}

// Fully opaque entries, NaN and infinite voxels render finite images.
TEST(CpuPreintegration, OpaqueNanAndInfiniteVoxelsStayFinite) {
  VolumeDesc v;
  v.extent = {16, 16, 16};
  v.type = VoxelType::f32;
  v.ranges = {ValueRange{0.0, 1.0}};
  FunctionSource src(v, bricks8(), [](std::uint32_t, const glm::u64vec3& p) {
    const std::uint64_t k = (p.x * 7 + p.y * 13 + p.z * 29) % 11;
    return k == 0   ? std::numeric_limits<double>::quiet_NaN()
           : k == 1 ? std::numeric_limits<double>::infinity()
           : k == 2 ? -std::numeric_limits<double>::infinity()
                    : double(k) / 10.0 - 0.2;
  });
  ResidentScene rs(src, {0});
  Scene scene = make_scene(24, oblique_camera());
  scene.channels = {
      make_channel(0, {{0.0, {0, 0, 1, 0.0}}, {0.5, {1, 0, 0, 1.0}}, {1.0, {1, 1, 0, 1.0}}}, 0, 0)};
  scene.preintegration = true;
  for (double step : {0.25, 2.0}) {
    scene.step_scale = step;
    const Rendered r = render_cpu(rs, scene);
    EXPECT_FALSE(has_nan(r.image));
    EXPECT_GT(r.stats.samples, 0u);
    for (const glm::vec4& p : r.image.pixels()) {
      EXPECT_TRUE(p.r >= 0.0f && p.r <= 1.0f && p.a >= 0.0f && p.a <= 1.0f);
    }
  }
}

}  // namespace
}  // namespace resoct::test
