// Jittered accumulation on the CPU backend (docs/rendering.md "Jittered accumulation"): a zero
// jitter renders the plain frame bit for bit, the sub-pixel offset moves the image plane as a
// camera shift does, and averaging jittered frames of a high-frequency volume comes closer to an
// independently supersampled reference than one frame does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/render/frame_accumulator.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

constexpr std::uint32_t kSize = 32;

std::shared_ptr<const BrickSource> turbulence() {
  return make_procedural_source("procedural:turbulence:64x64x64", BrickLayout{glm::uvec3(16), 1});
}

Scene scene_of(const BrickSource& src, std::uint32_t size = kSize) {
  Scene s = overview_scene(src.hierarchy().volume(), Viewport{size, size});
  // Level 0 at every resolution: the supersampled reference must show the same data.
  s.lod_error_px = 0.01;
  return s;
}

std::unique_ptr<Renderer> sync_renderer(std::shared_ptr<const BrickSource> src) {
  ViewerOptions v;
  v.loader_threads = 0;
  return std::make_unique<Renderer>(std::move(src), cpu::make_backend(2), v);
}

double rms(const Image& a, const Image& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const glm::vec4 d = a.pixels()[i] - b.pixels()[i];
    s += double(glm::dot(d, d));
  }
  return std::sqrt(s / double(a.pixels().size() * 4));
}

double max_abs(const Image& a, const Image& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    for (int c = 0; c < 4; ++c) {
      m = std::max(m, double(std::abs(a.pixels()[i][c] - b.pixels()[i][c])));
    }
  }
  return m;
}

TEST(CpuJitter, ZeroJitterIsBitIdenticalToNoJitterAndOtherJitterIsNot) {
  const auto src = turbulence();
  const Scene scene = scene_of(*src);
  auto r = sync_renderer(src);
  const ConvergeReport plain = r->render_until_converged(scene, 64);
  ASSERT_TRUE(plain.converged);
  FrameReport zero;
  r->render_frame(scene, zero, FrameJitter{});
  EXPECT_EQ(zero.image, plain.last.image);
  EXPECT_EQ(zero.stats.backend.samples, plain.last.stats.backend.samples);
  // The test could fail: each kind of jitter alone changes the picture.
  for (const FrameJitter j : {FrameJitter{0.25f, 0.0f, 0.0f}, FrameJitter{0.0f, -0.25f, 0.0f},
                              FrameJitter{0.0f, 0.0f, 0.3f}}) {
    FrameReport moved;
    r->render_frame(scene, moved, j);
    const double d = max_abs(moved.image, plain.last.image);
    std::printf("[ jitter ] (%.2f, %.2f, %.2f): max difference %.4f\n", j.pixel_x, j.pixel_y,
                j.sample, d);
    EXPECT_GT(d, 1e-3);
  }
}

TEST(CpuJitter, SubPixelOffsetEqualsAnOrthographicCameraShift) {
  const auto src = turbulence();
  Scene scene = scene_of(*src);
  scene.camera.projection = Projection::orthographic;
  scene.camera.ortho_height = 1.2;
  auto r = sync_renderer(src);
  ASSERT_TRUE(r->render_until_converged(scene, 64).converged);
  // jitter (+x pixels, +y pixels down) = the eye moved right by x pixels and down by y pixels.
  const double pixel = scene.camera.ortho_height / double(kSize);
  const glm::dvec3 forward = glm::normalize(scene.camera.target - scene.camera.eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, scene.camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const FrameJitter j{0.375f, -0.25f, 0.0f};
  Scene shifted = scene;
  const glm::dvec3 d = right * (double(j.pixel_x) * pixel) - up * (double(j.pixel_y) * pixel);
  shifted.camera.eye += d;
  shifted.camera.target += d;
  FrameReport jittered, moved, plain;
  r->render_frame(scene, jittered, j);
  r->render_frame(shifted, moved);
  r->render_frame(scene, plain);
  const double same = max_abs(jittered.image, moved.image);
  const double unlike = max_abs(plain.image, moved.image);
  std::printf("[ jitter ] orthographic: jitter vs shifted camera %.2e, plain vs shifted %.2e\n",
              same, unlike);
  EXPECT_LT(same, 2e-3);
  EXPECT_GT(unlike, 20.0 * same);
}

TEST(CpuJitter, AccumulationApproachesASupersampledReference) {
  const auto src = turbulence();
  const Scene scene = scene_of(*src);
  // The reference, independent of the jitter: the plain kernel at 4x4 the pixels (a box filter
  // of 16 sub-pixel rays per pixel) and an eighth of the step, averaged per pixel here.
  constexpr std::uint32_t kSuper = 4;
  Scene fine = scene_of(*src, kSize * kSuper);
  fine.step_scale = scene.step_scale / 8.0;
  auto rf = sync_renderer(src);
  const ConvergeReport big = rf->render_until_converged(fine, 64);
  ASSERT_TRUE(big.converged);
  Image reference(kSize, kSize);
  for (std::uint32_t y = 0; y < kSize * kSuper; ++y) {
    for (std::uint32_t x = 0; x < kSize * kSuper; ++x) {
      reference.at(x / kSuper, y / kSuper) += big.last.image.at(x, y) / float(kSuper * kSuper);
    }
  }
  auto r = sync_renderer(src);
  const ConvergeReport one = r->render_until_converged(scene, 64);
  ASSERT_TRUE(one.converged);
  const double e1 = rms(one.last.image, reference);
  const Image acc4 = render_accumulated(*r, scene, 4);
  const Image acc32 = render_accumulated(*r, scene, 32);
  const double e4 = rms(acc4, reference), e32 = rms(acc32, reference);
  std::printf(
      "[ jitter ] RMS error against the 4x4 supersampled reference: 1 frame %.5f, "
      "4 frames %.5f, 32 frames %.5f\n",
      e1, e4, e32);
  EXPECT_LT(e4, e1);
  EXPECT_LT(e32, 0.6 * e1);
  EXPECT_LT(e32, e4);
}

TEST(CpuJitter, RendererRejectsAJitterOutOfRangeNamingIt) {
  const auto src = turbulence();
  const Scene scene = scene_of(*src);
  auto r = sync_renderer(src);
  FrameReport report;
  r->render_frame(scene, report);
  const std::uint64_t frame = r->frame_index();
  EXPECT_RESOCT_ERROR(r->render_frame(scene, report, FrameJitter{0.5f, 0.0f, 0.0f}),
                      ErrorCode::invalid_argument, "jitter.pixel_x");
  EXPECT_RESOCT_ERROR(r->render_frame(scene, report, FrameJitter{0.0f, -0.6f, 0.0f}),
                      ErrorCode::invalid_argument, "jitter.pixel_y");
  EXPECT_RESOCT_ERROR(r->render_frame(scene, report, FrameJitter{0.0f, 0.0f, NAN}),
                      ErrorCode::invalid_argument, "jitter.sample");
  EXPECT_EQ(r->frame_index(), frame);  // nothing rendered
}

}  // namespace
}  // namespace resoct::test
