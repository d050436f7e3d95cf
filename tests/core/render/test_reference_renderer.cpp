// The oracle itself: analytic transmittance of a constant medium for any step, exact trilinear
// reproduction of linear ramps, transparent/opaque transfer functions and the intermixing rule.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "support/expect_error.hpp"
#include "support/reference_renderer.hpp"

namespace {

using namespace resoct;
using resoct::test::ReferenceOptions;
using resoct::test::VoxelFunction;

VoxelFunction constant(double v) {
  return [v](std::uint32_t, const glm::i64vec3&) { return v; };
}

ChannelSettings channel(std::uint32_t c, double alpha, glm::dvec3 rgb = glm::dvec3(1.0)) {
  ChannelSettings s;
  s.channel = c;
  s.tf = TransferFunction({{0.0, glm::dvec4(rgb, alpha)}, {1.0, glm::dvec4(rgb, alpha)}});
  return s;
}

Scene base_scene() {
  Scene s;
  s.camera.eye = {0.5, 0.5, 3.0};
  s.camera.target = {0.5, 0.5, 0.5};
  s.viewport = {16, 16};
  s.ert_opacity = 1.0;
  return s;
}

TEST(ReferenceRenderer, ConstantMediumMatchesClosedFormForAnyStep) {
  // 1 − exp(−σL) with σ = −ln(1 − α)/Δ₀, for axis-aligned and diagonal rays, steps 1/16..4 Δ₀
  // (and a step that does not divide L). Tolerance 1e-9: the only error is double rounding,
  // because the last partial segment gets its own opacity correction.
  VolumeDesc v;
  v.extent = {32, 16, 8};
  v.spacing = {1.0, 1.0, 2.0};  // physical 32 x 16 x 16: box (1, 0.5, 0.5), Δ₀ = 1/32
  v.type = VoxelType::f32;
  Scene s = base_scene();
  const double alpha = 0.07;
  s.channels = {channel(0, alpha)};
  const double delta0 = 1.0 / 32.0;
  ASSERT_DOUBLE_EQ(resoct::test::reference_step(v), delta0);
  const double sigma = -std::log(1.0 - alpha) / delta0;
  struct Case {
    Ray ray;
    double length;
  };
  const double s3 = 1.0 / std::sqrt(3.0);
  const Case cases[] = {
      {Ray{{-1.0, 0.25, 0.25}, {1.0, 0.0, 0.0}}, 1.0},
      {Ray{{0.5, 0.25, 2.0}, {0.0, 0.0, -1.0}}, 0.5},
      {Ray{{0.3, -0.5, 0.1}, {0.0, 1.0, 0.0}}, 0.5},
      {Ray{{0.25, 0.0, 0.0}, {0.0, 0.0, 1.0}}, 0.5},  // on two lower faces: inside
      {Ray{{0.0, 0.0, 0.0}, {s3, s3, s3}}, 0.5 * std::sqrt(3.0)},
      {Ray{{0.5, 0.25, 0.25}, {1.0, 0.0, 0.0}}, 0.5},  // origin inside
  };
  for (double step : {1.0 / 16, 1.0 / 8, 1.0 / 4, 0.3, 1.0 / 2, 1.0, 2.0, 4.0}) {
    for (const Case& c : cases) {
      ReferenceOptions o;
      o.step = step;
      const glm::dvec4 acc = resoct::test::reference_ray(s, v, constant(0.5), c.ray, o);
      const double expect = 1.0 - std::exp(-sigma * c.length);
      EXPECT_NEAR(acc.a, expect, 1e-9) << "step " << step;
      EXPECT_NEAR(acc.r, expect, 1e-9) << "step " << step;
    }
  }
  // A ray on an upper face misses.
  const glm::dvec4 miss = resoct::test::reference_ray(
      s, v, constant(0.5), Ray{{-1.0, 0.5, 0.25}, {1.0, 0.0, 0.0}}, ReferenceOptions{});
  EXPECT_EQ(miss, glm::dvec4(0.0));
}

TEST(ReferenceRenderer, OrthographicImageOfConstantBox) {
  // Orthographic view along -z of a unit cube: pixels inside the footprint have colour
  // 1 − exp(−σ) over black, the others show the background.
  VolumeDesc v;
  v.extent = {8, 8, 8};
  Scene s = base_scene();
  s.camera.projection = Projection::orthographic;
  s.camera.ortho_height = 2.0;  // 16 px over 2 units: the cube covers the middle 8 x 8
  s.background = {0.0, 0.0, 1.0, 1.0};
  s.channels = {channel(0, 0.2, {1.0, 0.0, 0.0})};
  const Image img = resoct::test::render_reference(s, v, constant(100.0));
  const double expect = 1.0 - std::pow(0.8, 8.0);
  for (std::uint32_t y = 0; y < 16; ++y) {
    for (std::uint32_t x = 0; x < 16; ++x) {
      const bool inside = x >= 4 && x < 12 && y >= 4 && y < 12;
      const glm::vec4 p = img.at(x, y);
      EXPECT_NEAR(p.r, inside ? expect : 0.0, 1e-6) << x << "," << y;
      EXPECT_NEAR(p.b, inside ? 1.0 - expect : 1.0, 1e-6) << x << "," << y;
      EXPECT_FLOAT_EQ(p.a, 1.0f);
    }
  }
}

TEST(ReferenceRenderer, TrilinearReproducesLinearRampsExactly) {
  const glm::u64vec3 extent(7, 5, 11);
  const glm::dvec4 k(0.3, -1.7, 2.25, 4.0);
  const VoxelFunction ramp = [&](std::uint32_t, const glm::i64vec3& i) {
    return k.x * (double(i.x) + 0.5) + k.y * (double(i.y) + 0.5) + k.z * (double(i.z) + 0.5) + k.w;
  };
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 2000; ++n) {
    const glm::dvec3 pos = glm::dvec3(u(rng), u(rng), u(rng)) * glm::dvec3(extent);
    // Between the outermost voxel centres the ramp is exact; beyond them clamp-to-edge holds
    // the value of the nearest centre plane.
    const glm::dvec3 c = glm::clamp(pos, glm::dvec3(0.5), glm::dvec3(extent) - 0.5);
    const double expect = k.x * c.x + k.y * c.y + k.z * c.z + k.w;
    EXPECT_NEAR(resoct::test::sample_trilinear(ramp, 0, extent, pos), expect, 1e-12);
  }
  // One-voxel-thick axis: constant along it.
  const glm::u64vec3 thin(4, 4, 1);
  EXPECT_NEAR(resoct::test::sample_trilinear(ramp, 0, thin, {1.0, 2.0, 0.9}),
              k.x * 1.0 + k.y * 2.0 + k.z * 0.5 + k.w, 1e-12);
}

TEST(ReferenceRenderer, TransparentAndOpaqueTransferFunctions) {
  VolumeDesc v;
  v.extent = {8, 8, 8};
  Scene s = base_scene();
  s.background = {0.2, 0.4, 0.6, 1.0};
  ChannelSettings c;
  c.tf = TransferFunction({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0}}});
  s.channels = {c};
  const Image clear = resoct::test::render_reference(s, v, constant(128.0));
  for (const glm::vec4& p : clear.pixels()) {
    EXPECT_EQ(p, glm::vec4(glm::dvec4(0.2, 0.4, 0.6, 1.0)));
  }
  // Opaque: the first sample stops the ray with exactly the TF colour wherever the box is hit.
  s.channels[0].tf = TransferFunction({{0.0, {0.9, 0.1, 0.3, 1}}});
  s.ert_opacity = 0.99;
  const Image solid = resoct::test::render_reference(s, v, constant(128.0));
  const CameraRays rays(s.camera, s.viewport);
  int hits = 0;
  for (std::uint32_t y = 0; y < 16; ++y) {
    for (std::uint32_t x = 0; x < 16; ++x) {
      const glm::dvec2 t =
          resoct::test::reference_ray_box(rays.pixel_ray(x, y), glm::dvec3(0.0), glm::dvec3(1.0));
      const glm::vec4 expect =
          t.x < t.y ? glm::vec4(0.9f, 0.1f, 0.3f, 1.0f) : glm::vec4(0.2f, 0.4f, 0.6f, 1.0f);
      hits += t.x < t.y ? 1 : 0;
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(solid.at(x, y)[k], expect[k], 1e-6);
    }
  }
  EXPECT_GT(hits, 10);
}

TEST(ReferenceRenderer, TwoIdenticalChannelsEqualOneDenserChannel) {
  // Intermixing: two channels of reference alpha a and the same colour combine to
  // 1 − (1 − a)^2 per reference step, i.e. one channel with that alpha, for any step.
  VolumeDesc v;
  v.extent = {8, 8, 8};
  v.channels = 2;
  Scene two = base_scene();
  two.channels = {channel(0, 0.1, {0.2, 0.5, 0.9}), channel(1, 0.1, {0.2, 0.5, 0.9})};
  Scene one = base_scene();
  one.channels = {channel(0, 1.0 - 0.9 * 0.9, {0.2, 0.5, 0.9})};
  ReferenceOptions o;
  o.step = 0.37;
  const Image a = resoct::test::render_reference(two, v, constant(0.5), o);
  const Image b = resoct::test::render_reference(one, v, constant(0.5), o);
  EXPECT_LT(compare_images(a, b).max_abs.r, 1e-6);
  EXPECT_LT(compare_images(a, b).max_abs.b, 1e-6);
  // The two channels' colours mix by weight: red and blue channels of equal alpha give purple.
  Scene rb = base_scene();
  rb.channels = {channel(0, 0.1, {1, 0, 0}), channel(1, 0.1, {0, 0, 1})};
  const Image c = resoct::test::render_reference(rb, v, constant(0.5), o);
  const glm::vec4 mid = c.at(8, 8);
  EXPECT_NEAR(mid.r, mid.b, 1e-6);
  EXPECT_GT(mid.r, 0.1f);
}

TEST(ReferenceRenderer, DefaultStepHasConverged) {
  // A smooth random two-channel field seen in perspective: halving the default step of 1/16
  // voxel changes the image by far less than one 8-bit level, so the oracle's step is "tiny".
  VolumeDesc v;
  v.extent = {12, 10, 9};
  v.channels = 2;
  v.type = VoxelType::f32;
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::vector<double>> data(2, std::vector<double>(12 * 10 * 9));
  for (auto& ch : data) {
    for (double& x : ch) x = u(rng);
  }
  const VoxelFunction voxels = resoct::test::dense_voxels(v.extent, data);
  Scene s;
  s.camera.eye = {1.8, 0.9, 1.6};
  s.camera.target = {0.5, 0.4, 0.4};
  s.viewport = {24, 24};
  ChannelSettings a;
  a.channel = 0;
  a.tf = TransferFunction({{0.2, {1, 0.5, 0, 0}}, {0.8, {1, 0.8, 0.2, 0.3}}});
  ChannelSettings b;
  b.channel = 1;
  b.tf = TransferFunction({{0.4, {0, 0.3, 1, 0}}, {1.0, {0.2, 0.6, 1, 0.5}}});
  s.channels = {a, b};
  const Image fine =
      resoct::test::render_reference(s, v, voxels, ReferenceOptions{1.0 / 32.0, true});
  const Image dflt = resoct::test::render_reference(s, v, voxels);
  const ImageDiff d = compare_images(fine, dflt);
  EXPECT_LT(d.max_abs.r, 0.5 / 255.0);
  EXPECT_LT(d.max_abs.g, 0.5 / 255.0);
  EXPECT_LT(d.max_abs.b, 0.5 / 255.0);
  // And the image is not trivially empty.
  double sum = 0.0;
  for (const glm::vec4& p : dflt.pixels()) sum += p.r + p.b;
  EXPECT_GT(sum, 1.0);
  EXPECT_RESOCT_ERROR(resoct::test::dense_voxels(v.extent, {std::vector<double>(5)}),
                      ErrorCode::size_mismatch, "channel 0 has 5 values");
}

}  // namespace
