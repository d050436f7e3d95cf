// Slice planes through the CPU backend against brute-force definitions: the analytic ramp seen
// on a plane, trilinear level-0 values across brick borders (no seam), the level the pixel
// footprint picks (asserted on the request set), substitution of a missing level, and
// depth-correct compositing with the volume (closed form).
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "resoct/scene/camera.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

// Looks down -z at the middle of the unit box, orthographic, covering `height` box units.
Camera ortho_down_z(double height) {
  Camera c;
  c.eye = {0.5, 0.5, 2.0};
  c.target = {0.5, 0.5, 0.5};
  c.projection = Projection::orthographic;
  c.ortho_height = height;
  return c;
}

const std::vector<TfPoint> kInvisible = {{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0}}};

SlicePlane grey_plane(glm::dvec3 point, glm::dvec3 normal, std::uint32_t channel) {
  SlicePlane p;
  p.point = point;
  p.normal = normal;
  p.channels = {channel};
  p.window = 1.0;  // grey = normalized value
  p.level = 0.5;
  return p;
}

// Where the pixel's ray meets the plane (box units), if inside the volume box.
std::optional<glm::dvec3> plane_hit(const CameraRays& rays, std::uint32_t x, std::uint32_t y,
                                    const SlicePlane& p, const glm::dvec3& box) {
  const Ray r = rays.pixel_ray(x, y);
  const double t = glm::dot(p.point - r.origin, p.normal) / glm::dot(r.dir, p.normal);
  if (!(t >= 0.0)) return std::nullopt;
  const glm::dvec3 q = r.origin + t * r.dir;
  for (int a = 0; a < 3; ++a) {
    if (!(q[a] >= 0.0 && q[a] < box[a])) return std::nullopt;
  }
  return q;
}

TEST(CpuSlices, RampShowsExactValues) {
  ProceduralSource src("procedural:ramp:64x48x40", bricks8());
  const VolumeDesc& vol = src.hierarchy().volume();
  ResidentScene rs(src, {0});
  Scene s = make_scene(64, ortho_down_z(1.1));
  s.channels = {make_channel(0, kInvisible)};  // the volume itself shows nothing
  s.lod_error_px = 0.5;                        // level 0 on the plane
  s.slices = {grey_plane({0.5, 0.4, 0.31}, {0.3, -0.2, 1.0}, 0)};
  const Rendered r = render_cpu(rs, s);
  EXPECT_TRUE(r.bricks.empty());
  EXPECT_EQ(r.stats.cap_hits, 0u);

  const CameraRays rays(s.camera, s.viewport);
  const glm::dvec3 box = box_extent(vol);
  const glm::dvec3 per_box = glm::dvec3(vol.extent) / box;
  const ValueRange range = vol.range(0);
  std::uint32_t on_plane = 0;
  double worst = 0.0;
  for (std::uint32_t y = 0; y < 64; ++y) {
    for (std::uint32_t x = 0; x < 64; ++x) {
      const glm::vec4 px = r.image.at(x, y);
      const auto q = plane_hit(rays, x, y, s.slices[0], box);
      if (!q) {
        EXPECT_EQ(px, glm::vec4(0, 0, 0, 1)) << x << "," << y;
        continue;
      }
      ++on_plane;
      // Channel 0 ramps along x: voxel i holds (i + 0.5) / W, so the trilinear field is x / W
      // between the first and last voxel centres and clamps outside them.
      const double w = double(vol.extent.x);
      const double xv = std::clamp(q->x * per_box.x, 0.5, w - 0.5);
      const double expected = (xv / w - range.lo) / (range.hi - range.lo);
      worst = std::max(worst, std::abs(double(px.r) - expected));
      EXPECT_EQ(px.a, 1.0f);
      EXPECT_EQ(px.r, px.g);
    }
  }
  EXPECT_GT(on_plane, 2000u);
  EXPECT_LT(worst, 2e-6);
}

// Planes on and next to a brick border (level-0 bricks are 8 voxels) and a tilted plane across
// many bricks: the sphere field, nonlinear, equals the level-0 trilinear definition everywhere.
TEST(CpuSlices, NoSeamAtBrickBorders) {
  ProceduralSource src("procedural:sphere:48x48x48", bricks8());
  const VolumeDesc& vol = src.hierarchy().volume();
  const VoxelFunction voxels = level0_voxels(src);
  ResidentScene rs(src, {0});
  const glm::dvec3 per_box = glm::dvec3(vol.extent);
  const ValueRange range = vol.range(0);
  for (const double z : {24.0, 24.0 + 1e-4, 24.0 - 1e-4, 16.5}) {
    for (const glm::dvec3 normal : {glm::dvec3(0, 0, 1), glm::dvec3(0.4, 0.7, 1.0)}) {
      Scene s = make_scene(48, ortho_down_z(1.0));
      s.channels = {make_channel(0, kInvisible)};
      s.lod_error_px = 0.5;
      s.slices = {grey_plane({0.5, 0.5, z / 48.0}, normal, 0)};
      const Rendered r = render_cpu(rs, s);
      ASSERT_TRUE(r.bricks.empty());
      const CameraRays rays(s.camera, s.viewport);
      double worst = 0.0;
      std::uint32_t hits = 0;
      for (std::uint32_t y = 0; y < 48; ++y) {
        for (std::uint32_t x = 0; x < 48; ++x) {
          const auto q = plane_hit(rays, x, y, s.slices[0], glm::dvec3(1.0));
          if (!q) continue;
          ++hits;
          const double raw = sample_trilinear(voxels, 0, vol.extent, *q * per_box);
          const double expected = std::clamp((raw - range.lo) / (range.hi - range.lo), 0.0, 1.0);
          worst = std::max(worst, std::abs(double(r.image.at(x, y).r) - expected));
        }
      }
      EXPECT_GT(hits, 500u);
      EXPECT_LT(worst, 1e-5) << "z " << z << " normal " << normal.x;
    }
  }
}

// With nothing resident, the requests of a slice name exactly the bricks of the level its pixel
// footprint picks, at the points where the pixel rays meet the plane.
TEST(CpuSlices, LevelFollowsFootprint) {
  ProceduralSource src("procedural:ramp:128x128x128", bricks8());
  ResidentOptions none;
  none.level_resident = [](std::uint32_t) { return false; };
  ResidentScene rs(src, {0}, none);
  const std::uint32_t rows = 16;
  for (std::uint32_t k = 0; k < 4; ++k) {
    for (const bool oblique : {false, true}) {
      // Footprint of 2^k voxels; lod_error_px 1.5 keeps level k (1.5 · 2^k < 2^(k+1)); an
      // oblique plane at 45° stretches the footprint by √2 and picks level k + 1.
      Scene s = make_scene(rows, ortho_down_z(double(rows << k) / 128.0));
      s.channels = {make_channel(0, kInvisible)};
      s.lod_error_px = 1.5;
      const glm::dvec3 normal = oblique ? glm::dvec3(1, 0, 1) : glm::dvec3(0, 0, 1);
      s.slices = {grey_plane({0.5, 0.5, 0.5 + 3.3 / 128.0}, normal, 0)};
      const Rendered r = render_cpu(rs, s);
      const std::uint32_t level = k + (oblique ? 1u : 0u);
      std::set<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>> got, want;
      for (const Request& q : r.bricks) {
        const PageAddress a = rs.decode(q.key);
        got.insert({a.level, a.brick.x, a.brick.y, a.brick.z});
      }
      const CameraRays rays(s.camera, s.viewport);
      const glm::uvec3 level_bricks = src.hierarchy().level(level).bricks;
      for (std::uint32_t y = 0; y < rows; ++y) {
        for (std::uint32_t x = 0; x < rows; ++x) {
          const auto p = plane_hit(rays, x, y, s.slices[0], glm::dvec3(1.0));
          if (!p) continue;
          const glm::dvec3 v = glm::floor(*p * 128.0 / double(1u << level) / 8.0);
          const glm::uvec3 b = glm::min(glm::uvec3(v), level_bricks - 1u);
          want.insert({level, b.x, b.y, b.z});
        }
      }
      EXPECT_FALSE(want.empty());
      EXPECT_EQ(got, want) << "k " << k << " oblique " << oblique;
    }
  }
}

// Level 0 missing, level 1 resident: the slice requests level 0 and shows level 1's trilinear
// values meanwhile.
TEST(CpuSlices, MissingLevelIsSubstituted) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  ResidentOptions only1;
  only1.level_resident = [](std::uint32_t l) { return l == 1; };
  ResidentScene rs(src, {0}, only1);
  Scene s = make_scene(32, ortho_down_z(1.0));
  s.channels = {make_channel(0, kInvisible)};
  s.lod_error_px = 0.5;
  s.slices = {grey_plane({0.5, 0.5, 13.3 / 32.0}, {0, 0, 1}, 0)};
  const Rendered r = render_cpu(rs, s);
  ASSERT_FALSE(r.bricks.empty());
  for (const Request& q : r.bricks) EXPECT_EQ(rs.decode(q.key).level, 0u);

  // Level 1 voxels by brute force: each averages its 2x2x2 level-0 voxels.
  const VolumeDesc& vol = src.hierarchy().volume();
  const glm::u64vec3 e1 = src.hierarchy().level(1).extent;
  std::vector<float> l1(std::size_t(e1.x * e1.y * e1.z));
  src.read_region(1, 0, Box3{glm::i64vec3(0), glm::i64vec3(e1)},
                  std::as_writable_bytes(std::span<float>(l1)));
  std::vector<double> l1d(l1.begin(), l1.end());
  const VoxelFunction level1 = dense_voxels(e1, {l1d});
  const ValueRange range = vol.range(0);
  const CameraRays rays(s.camera, s.viewport);
  double worst = 0.0;
  for (std::uint32_t y = 0; y < 32; ++y) {
    for (std::uint32_t x = 0; x < 32; ++x) {
      const auto q = plane_hit(rays, x, y, s.slices[0], glm::dvec3(1.0));
      ASSERT_TRUE(q.has_value());
      const double raw = sample_trilinear(level1, 0, e1, *q * 32.0 / 2.0);
      const double expected = std::clamp((raw - range.lo) / (range.hi - range.lo), 0.0, 1.0);
      worst = std::max(worst, std::abs(double(r.image.at(x, y).r) - expected));
    }
  }
  EXPECT_LT(worst, 1e-5);
}

// A constant medium in front of an opaque slice and behind it: the pixel is the medium's
// closed-form opacity over the slice's grey, and nothing behind the slice shows.
TEST(CpuSlices, CompositedDepthCorrectly) {
  ProceduralSource src("procedural:constant:32x32x32", bricks8());
  ResidentScene rs(src, {0});
  const double a = 0.05;
  const glm::dvec3 rgb(0.9, 0.3, 0.1);
  Scene s = make_scene(16, ortho_down_z(0.5));
  s.channels = {
      make_channel(0, {{0.0, {rgb.r, rgb.g, rgb.b, a}}, {1.0, {rgb.r, rgb.g, rgb.b, a}}})};
  s.step_scale = 1.0;
  for (const double depth_vox : {16.0, 5.0, 27.25}) {
    SlicePlane p = grey_plane({0.5, 0.5, depth_vox / 32.0}, {0, 0, 1}, 0);
    p.level = 0.3;  // constant 0.5 → grey 0.7
    s.slices = {p};
    const Rendered r = render_cpu(rs, s);
    // Rays run down from z = 1: the medium in front of the slice is 32 - depth voxels thick.
    const double front = 1.0 - std::pow(1.0 - a, 32.0 - depth_vox);
    const glm::dvec3 expected = rgb * front + (1.0 - front) * glm::dvec3(0.7);
    for (std::uint32_t y = 0; y < 16; ++y) {
      for (std::uint32_t x = 0; x < 16; ++x) {
        const glm::vec4 px = r.image.at(x, y);
        EXPECT_NEAR(px.a, 1.0, 1e-6);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(px[c], expected[c], 2e-4) << depth_vox;
      }
    }
  }
}

// Without slices or lens the frame fields stay zero and the image is bit-identical to the same
// scene rendered before slices existed (slice fields are the only difference in the tables).
TEST(CpuSlices, PlainSceneUnchangedBySliceSupport) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  ResidentScene rs(src, {0});
  Camera cam;
  cam.eye = {1.9, 1.3, 2.1};
  cam.target = {0.5, 0.5, 0.5};
  Scene s = make_scene(32, cam);
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}, {1.0, {1, 0.5, 0.2, 0.3}}})};
  const FrameTables t = rs.tables(s);
  EXPECT_EQ(t.frame.slice_count, 0u);
  EXPECT_EQ(t.frame.lens_enabled, 0u);
  EXPECT_EQ(t.slots.size(), 1u);
  // A slice entirely outside the view changes nothing either.
  const Rendered plain = render_cpu(rs, s);
  s.slices = {grey_plane({0.5, 0.5, 0.5}, {0, 0, 1}, 0)};
  s.slices[0].point = {0.5, 0.5, -5.0};
  const Rendered with_far_slice = render_cpu(rs, s);
  EXPECT_EQ(max_diff(plain.image, with_far_slice.image), 0.0);
  EXPECT_EQ(plain.stats.samples, with_far_slice.stats.samples);
}

}  // namespace
}  // namespace resoct::test
