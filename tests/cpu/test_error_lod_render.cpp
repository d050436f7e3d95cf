// Error-bounded LOD through the Renderer: the loader measures coarse bricks' errors
// (ViewerOptions::brick_errors), the page entries carry them, a view refines level by level to
// the image the everything-resident set-up gives, with fewer bricks than the footprint needs;
// and a scene that asks for it from a renderer that measures nothing is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "cpu/cpu_test_util.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/render/renderer.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

std::shared_ptr<const ProceduralSource> sphere() {
  BrickLayout l;
  l.brick_size = glm::uvec3(16);
  return std::make_shared<const ProceduralSource>("procedural:sphere:64x64x64", l);
}

Scene sphere_scene() {
  Camera cam;
  cam.eye = {0.5, 0.62, 1.7};
  cam.target = {0.5, 0.5, 0.5};
  Scene s = make_scene(48, cam);
  s.lod_error_px = 0.5;
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}},
                                 {0.01, {1, 1, 1, 0}},
                                 {0.4, {1, 0.5, 0.2, 0.1}},
                                 {1.0, {0.2, 0.5, 1.0, 0.4}}})};
  return s;
}

ViewerOptions sync(bool brick_errors) {
  ViewerOptions v;
  v.loader_threads = 0;
  v.brick_errors = brick_errors;
  return v;
}

std::uint64_t uploads_until_converged(Renderer& r, const Scene& s, Image& last) {
  std::uint64_t uploaded = 0;
  for (int i = 0; i < 64; ++i) {
    const FrameReport f = r.render_frame(s);
    uploaded += f.stats.bricks_uploaded;
    last = f.image;
    if (f.converged) return uploaded;
  }
  ADD_FAILURE() << "no convergence in 64 frames";
  return uploaded;
}

TEST(ErrorLodRender, ASceneAsksInVainWithoutMeasuredErrors) {
  Renderer r(sphere(), cpu::make_backend(1), sync(false));
  Scene s = sphere_scene();
  s.lod_error_color = 0.05;
  EXPECT_RESOCT_ERROR(r.render_frame(s), ErrorCode::invalid_argument, "lod_error_color");
  s.lod_error_color = 0.0;
  EXPECT_NO_THROW(r.render_frame(s));
  s.lod_error_color = 1.5;  // out of [0, 1]
  EXPECT_RESOCT_ERROR(r.render_frame(s), ErrorCode::invalid_argument, "lod_error_color");
}

TEST(ErrorLodRender, AViewRefinesToTheResidentImageWithFewerBricks) {
  const auto src = sphere();
  ResidentOptions o;
  o.brick_errors = true;
  const ResidentScene rs(*src, {0}, o);
  // The footprint alone needs level 0 wherever the view shows data.
  Renderer footprint(src, cpu::make_backend(1), sync(true));
  Image plain;
  const std::uint64_t footprint_bricks = uploads_until_converged(footprint, sphere_scene(), plain);
  for (double colour : {1.0, 0.125, 0.0625}) {
    Scene s = sphere_scene();
    s.lod_error_color = colour;
    const Image expected = render_cpu(rs, s).image;
    Renderer eb(src, cpu::make_backend(1), sync(true));
    Image got;
    const std::uint64_t eb_bricks = uploads_until_converged(eb, s, got);
    EXPECT_LE(max_diff(got, expected), 1e-6) << "colour error " << colour;
    // Measured: 1, 9 and 71 bricks against the footprint's 73 (at colour error 1 the one
    // coarsest brick holds the whole sphere).
    if (colour == 1.0) {
      EXPECT_EQ(eb_bricks, 1u);
    } else {
      EXPECT_LT(eb_bricks, footprint_bricks) << "colour error " << colour;
    }
  }
}

}  // namespace
}  // namespace resoct::test
