// Effects through the CPU backend (whole frames): the effect selection (no gradient or shadow
// code without effects), MIP/AIP against brute-force projections of the resident data, MIP with
// skipping equal to MIP without, isosurfaces without cracks across brick borders and level
// transitions, and a sphere's shadow on a slab where the geometry puts it.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "support/function_source.hpp"
#include "resoct/base/error.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

BrickLayout bricks8(std::uint32_t halo = 1) {
  return BrickLayout{glm::uvec3(8), halo};
}

std::vector<TfPoint> grey_ramp(double alpha) {
  return {{0.0, {0, 0, 0, 0}}, {1.0, {1, 1, 1, alpha}}};
}

TEST(CpuEffects, SceneWithoutEffectsRunsNoEffectCode) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  ResidentScene rs(src, {0});
  Scene s = make_scene(24, oblique_camera());
  s.channels = {make_channel(0, grey_ramp(0.1))};
  const Rendered plain = render_cpu(rs, s);
  EXPECT_EQ(plain.stats.gradient_evals, 0u);
  EXPECT_EQ(plain.stats.shadow_rays, 0u);
  EXPECT_GT(plain.stats.samples, 0u);

  s.effects = {Effect::shading};
  const Rendered shaded = render_cpu(rs, s);
  EXPECT_GT(shaded.stats.gradient_evals, 0u);
  EXPECT_EQ(shaded.stats.shadow_rays, 0u);
  // Shading changes colours, not where the ray samples.
  EXPECT_EQ(shaded.stats.samples, plain.stats.samples);
  EXPECT_GT(max_diff(shaded.image, plain.image), 1e-2);

  s.effects = {Effect::shading, Effect::shadows};
  const Rendered shadowed = render_cpu(rs, s);
  EXPECT_GT(shadowed.stats.shadow_rays, 0u);
  EXPECT_EQ(shadowed.stats.cap_hits, 0u);
}

// The brute-force projection of one pixel ray over the dense level-0 data (reference sampling:
// 1/16 of a voxel), normalized and clamped like the kernel.
double brute_projection(const Scene& s, const VolumeDesc& v, const VoxelFunction& vox, int px,
                        int py, bool average) {
  const CameraRays rays(s.camera, s.viewport);
  const Ray ray = rays.pixel_ray(std::uint32_t(px), std::uint32_t(py));
  const glm::dvec2 span = reference_ray_box(ray, glm::dvec3(0.0), box_extent(v));
  const double t0 = std::max(span.x, 0.0), t1 = span.y;
  if (!(t0 < t1)) return -1.0;
  const double step = reference_step(v) / 16.0;
  const glm::dvec3 to_vox = glm::dvec3(v.extent) / box_extent(v);
  const ValueRange r = v.range(0);
  double best = 0.0, sum = 0.0;
  for (double t = t0; t < t1; t += step) {
    const double seg = std::min(step, t1 - t);
    const glm::dvec3 p = (ray.origin + ray.dir * (t + 0.5 * seg)) * to_vox;
    const double x =
        std::clamp((sample_trilinear(vox, 0, v.extent, p) - r.lo) / (r.hi - r.lo), 0.0, 1.0);
    best = std::max(best, x);
    sum += x * seg;
  }
  return average ? sum / (t1 - t0) : best;
}

TEST(CpuEffects, MipAndAipMatchBruteForceProjections) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  const VolumeDesc& v = src.hierarchy().volume();
  const VoxelFunction vox = level0_voxels(src);
  for (ChannelMode mode : {ChannelMode::mip, ChannelMode::aip}) {
    ResidentScene rs(src, {0});
    Scene s = make_scene(20, oblique_camera());
    s.channels = {make_channel(0, {{0.0, {0, 0, 0, 1}}, {1.0, {1, 1, 1, 1}}}, 0, 0)};
    s.channels[0].mode = mode;
    const Rendered r = render_cpu(rs, s);
    EXPECT_EQ(r.stats.cap_hits, 0u);
    double worst = 0.0;
    int rays = 0;
    for (int y = 0; y < 20; ++y) {
      for (int x = 0; x < 20; ++x) {
        const double expect = brute_projection(s, v, vox, x, y, mode == ChannelMode::aip);
        if (expect < 0.0) continue;
        ++rays;
        // The grey ramp TF maps the projection to the colour (opaque, so the pixel is it).
        worst = std::max(
            worst, std::abs(double(r.image.at(std::uint32_t(x), std::uint32_t(y)).r) - expect));
      }
    }
    EXPECT_GT(rays, 100);
    // Sampling at 1/4 voxel instead of 1/16 (max of a smooth field: error <= slope * dt / 2)
    // and the 1024-entry LUT.
    EXPECT_LT(worst, 1.5e-2) << to_string(mode);
  }
}

// Fraction of pixels whose largest channel difference exceeds `tol`.
double fraction_above(const Image& a, const Image& b, double tol) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const glm::vec4 d = glm::abs(a.pixels()[i] - b.pixels()[i]);
    if (std::max({d.r, d.g, d.b, d.a}) > tol) ++bad;
  }
  return double(bad) / double(a.pixels().size());
}

// Shaded DVR and lit isosurfaces against the double-precision reference renderer (level 0,
// exact TF, 1/16 steps, exact crossings): the kernel samples at 1/4 voxel in float through a
// LUT, so colours differ by a few 1e-3; a pixel whose ray grazes the surface can miss (or
// catch) a crossing the finer reference catches (or misses), which bounds the share of
// differing pixels rather than their difference. Shaded DVR measured max 3.8e-3, RMSE 4.9e-4
// (both stencils); gradient taps two voxels away on one axis give max 0.12-0.19, RMSE 8e-3-2e-2.
TEST(CpuEffects, ShadingAndIsosurfacesMatchTheReferenceRenderer) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  const VolumeDesc& v = src.hierarchy().volume();
  const VoxelFunction vox = level0_voxels(src);
  ResidentScene rs(src, {0});
  Scene s = make_scene(40, oblique_camera());
  s.light.kind = Light::Kind::directional;
  s.light.vector = {-0.3, -1.0, -0.5};
  s.channels = {make_channel(
      0, {{0.0, {1, 1, 1, 0}}, {0.3, {1, 0.6, 0.2, 0.05}}, {1.0, {0.2, 0.4, 1.0, 0.3}}}, 0, 0)};
  s.effects = {Effect::shading};
  for (GradientStencil g : {GradientStencil::central, GradientStencil::forward}) {
    s.gradient = g;
    const Rendered r = render_cpu(rs, s);
    const Image ref = render_reference(s, v, vox);
    const ImageDiff d = compare_images(r.image, ref);
    EXPECT_LT(d.rmse_rgb, 1.5e-3) << "shaded dvr";
    EXPECT_LT(max_diff(r.image, ref), 1e-2) << "shaded dvr";
    std::printf("shaded DVR vs reference: max %.2e rmse %.2e\n", max_diff(r.image, ref),
                d.rmse_rgb);
  }
  s.effects = {Effect::shading};
  s.channels[0].mode = ChannelMode::iso;
  s.channels[0].isovalues = {0.45, 0.8};
  s.channels[0].tf = TransferFunction({{0.0, {1, 0.6, 0.2, 0.4}}, {1.0, {0.2, 0.5, 1.0, 1.0}}});
  const Rendered r = render_cpu(rs, s);
  const Image ref = render_reference(s, v, vox);
  EXPECT_GT(r.stats.gradient_evals, 0u);
  // Exact crossings on both sides: measured 0 pixels above 1e-3, RMSE 7e-8.
  EXPECT_LT(fraction_above(r.image, ref, 1e-3), 0.01) << "iso";
  EXPECT_LT(compare_images(r.image, ref).rmse_rgb, 1e-3) << "iso";
  std::printf("iso vs reference: %.2f%% pixels above 1e-3, rmse %.2e\n",
              100.0 * fraction_above(r.image, ref, 1e-3), compare_images(r.image, ref).rmse_rgb);
}

TEST(CpuEffects, MipWithSkippingEqualsMipWithout) {
  // Tubes: sparse, so whole nodes are skipped once the running maximum is reached.
  ProceduralSource src("procedural:tubes:48x48x48", bricks8());
  ResidentOptions no_meta;
  no_meta.metadata = false;
  ResidentScene with(src, {0});
  ResidentScene without(src, {0}, no_meta);
  Scene s = make_scene(32, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {0, 0, 0, 1}}, {1.0, {1, 0.5, 0.2, 1}}}, 0, 0)};
  for (ChannelMode mode : {ChannelMode::mip, ChannelMode::aip}) {
    s.channels[0].mode = mode;
    const Rendered a = render_cpu(with, s);
    const Rendered b = render_cpu(without, s);
    EXPECT_GT(a.stats.distance_skipped, 0.0) << to_string(mode);
    EXPECT_EQ(b.stats.distance_skipped, 0.0);
    EXPECT_LE(a.stats.samples, b.stats.samples);
    // Skips land on the unskipped sample grid, but t reached by one jump of k steps and by k
    // single steps differs by float rounding (~1e-5 box units here); the sharp tube edges turn
    // that into value differences of a few 1e-4 (the render modes agree to the same order).
    EXPECT_LE(max_diff(a.image, b.image), 1e-3) << to_string(mode);
  }
}

// A plane isosurface (ramp field, exact at every level) seen through bricks of 8 voxels where
// level 0 is resident only for x < 16: the surface continues through the level transition and
// every brick border without a crack, identical (to float rounding) to the fully resident
// frame, and covers exactly the pixels whose rays cross the plane.
TEST(CpuEffects, IsosurfaceAcrossBrickBordersAndLevelTransitions) {
  ProceduralSource src("procedural:ramp:32x32x32", bricks8(2));
  ResidentScene full(src, {0});
  ResidentOptions part;
  part.brick_resident = [](std::uint32_t level, glm::uvec3 b) { return level > 0 || b.x < 2; };
  ResidentScene partial(src, {0}, part);
  Scene s = make_scene(40, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {0.2, 0.6, 1.0, 1}}, {1.0, {0.2, 0.6, 1.0, 1}}}, 0, 15)};
  s.channels[0].mode = ChannelMode::iso;
  s.channels[0].isovalues = {0.5};
  s.lod_error_px = 1e-3;  // target level 0 everywhere; level 1 substitutes where it is missing
  const Rendered a = render_cpu(full, s);
  const Rendered b = render_cpu(partial, s);
  EXPECT_GT(a.stats.gradient_evals, 0u);
  EXPECT_LE(max_diff(a.image, b.image), 2e-3);
  // Coverage: a pixel shows the surface iff its ray crosses x = 0.5 inside the box.
  const CameraRays rays(s.camera, s.viewport);
  int covered = 0;
  for (std::uint32_t y = 0; y < 40; ++y) {
    for (std::uint32_t x = 0; x < 40; ++x) {
      const Ray ray = rays.pixel_ray(x, y);
      const glm::dvec2 span = reference_ray_box(ray, glm::dvec3(0.0), glm::dvec3(1.0));
      const double t = (0.5 - ray.origin.x) / ray.dir.x;
      const glm::dvec3 p = ray.origin + t * ray.dir;
      const double margin = 1.0 / 32.0;  // one voxel: the ramp's clamped border
      const bool inside =
          span.x < span.y && p.y > margin && p.y < 1 - margin && p.z > margin && p.z < 1 - margin;
      const bool outside = !(span.x < span.y) || p.y < -margin || p.y > 1 + margin ||
                           p.z < -margin || p.z > 1 + margin;
      const bool hit = b.image.at(x, y).b > 0.5f;
      if (inside) {
        EXPECT_TRUE(hit) << x << "," << y;
        ++covered;
      }
      if (outside) {
        EXPECT_FALSE(hit) << x << "," << y;
      }
    }
  }
  EXPECT_GT(covered, 200);
}

// Slab z in [2, 6) and a ball of radius 5 voxels at (20, 16, 20) in a 64x32x32 f32 volume, both
// value 1, rendered as the isosurface 0.5 from straight above (orthographic, one pixel per
// voxel) with a directional light travelling along (1, 0, −1): the ball's shadow on the slab is
// the ellipse with semi-axes 7.1 (x) and 5 (y) around (34, 16). Inside
// (>= 2 voxels from the edge) only ambient light remains, well outside the slab is lit,
// for shadow LOD factors 1 and 2.
TEST(CpuEffects, SphereShadowOnSlabWhereGeometrySays) {
  VolumeDesc v;
  v.extent = {64, 32, 32};
  v.type = VoxelType::f32;
  v.ranges = {ValueRange{0.0, 1.0}};
  const glm::dvec3 c(20.0, 16.0, 20.0);
  FunctionSource src(v, bricks8(), [c](std::uint32_t, const glm::u64vec3& p) {
    const glm::dvec3 q = glm::dvec3(p) + 0.5;
    return (q.z >= 2 && q.z < 6) || glm::length(q - c) < 5.0 ? 1.0 : 0.0;
  });
  ResidentScene rs(src, {0});
  Scene s;
  s.camera.projection = Projection::orthographic;
  s.camera.eye = {0.5, 0.25, 2.0};
  s.camera.target = {0.5, 0.25, 0.0};
  s.camera.up = {0, 1, 0};
  s.camera.ortho_height = 0.5;
  s.viewport = {64, 32};
  s.step_scale = 0.5;
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 1}}, {1.0, {1, 1, 1, 1}}}, 0, 0)};
  s.channels[0].mode = ChannelMode::iso;
  s.channels[0].isovalues = {0.5};
  s.effects = {Effect::shadows};
  s.light.kind = Light::Kind::directional;
  s.light.vector = {1.0, 0.0, -1.0};
  s.light.specular = 0.0;
  const double lit = s.light.ambient + s.light.diffuse * std::sqrt(0.5);  // n = +z
  for (std::uint32_t factor : {1u, 2u}) {
    s.shadow_lod_factor = factor;
    const Rendered r = render_cpu(rs, s);
    EXPECT_GT(r.stats.shadow_rays, 0u);
    const glm::dvec2 shadow(34.0, 16.0);
    int in = 0, out = 0;
    for (std::uint32_t py = 0; py < 32; ++py) {
      for (std::uint32_t px = 0; px < 64; ++px) {
        const glm::dvec2 p(px + 0.5, 32.0 - (py + 0.5));
        if (glm::length(p - glm::dvec2(20.0, 16.0)) < 7.0) continue;  // the ball itself
        if (p.x < 2 || p.x > 62 || p.y < 2 || p.y > 30) continue;     // clamped borders
        const double d = glm::length(p - shadow);
        const double grey = r.image.at(px, py).r;
        if (d < 3.0) {
          EXPECT_NEAR(grey, s.light.ambient, 0.02) << px << "," << py << " factor " << factor;
          ++in;
        } else if (d > 9.0) {
          EXPECT_NEAR(grey, lit, 0.02) << px << "," << py << " factor " << factor;
          ++out;
        }
      }
    }
    EXPECT_GT(in, 20);
    EXPECT_GT(out, 500);
  }
}

TEST(CpuEffects, HaloZeroIsRejectedForGradientEffects) {
  ProceduralSource src("procedural:sphere:16x16x16", BrickLayout{glm::uvec3(8), 0});
  ResidentScene rs(src, {0});
  Scene s = make_scene(8, oblique_camera());
  s.channels = {make_channel(0, grey_ramp(0.1))};
  EXPECT_NO_THROW(rs.tables(s));
  s.effects = {Effect::shading};
  try {
    rs.tables(s);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("halo"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resoct::test
