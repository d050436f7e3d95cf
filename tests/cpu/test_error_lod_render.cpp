// Error-bounded LOD through the Renderer: the loader measures coarse bricks' errors
// (ViewerOptions::brick_errors), the page entries carry them, a view refines level by level to
// the image the everything-resident set-up gives, with fewer bricks than the footprint needs;
// and a scene that asks for it from a renderer that measures nothing is refused.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "core/io/store/test_brick_store_util.hpp"
#include "cpu/cpu_test_util.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/io/store/brick_store.hpp"
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

// A source that claims every coarse brick is exact, and counts how often it is asked.
class ExactClaimSource final : public BrickSource {
 public:
  explicit ExactClaimSource(std::shared_ptr<const BrickSource> inner) : inner_(std::move(inner)) {}
  const BrickHierarchy& hierarchy() const override { return inner_->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    inner_->read_brick(key, out);
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_->region_meta(c, b);
  }
  double brick_error(BrickKey, std::span<const std::byte>) const override {
    asked_.fetch_add(1);
    return 0.0;
  }
  std::string name() const override { return "exact-claim"; }
  int asked() const { return asked_.load(); }

 private:
  std::shared_ptr<const BrickSource> inner_;
  mutable std::atomic<int> asked_{0};
};

TEST(ErrorLodRender, TheLoaderTakesTheErrorsTheSourceGives) {
  const auto src = std::make_shared<const ExactClaimSource>(sphere());
  Scene s = sphere_scene();
  s.lod_error_color = 0.0625;  // needs 71 measured bricks (above)
  Renderer r(src, cpu::make_backend(1), sync(true));
  Image got;
  // Every brick claims error 0, so the coarsest brick qualifies and holds the whole view.
  EXPECT_EQ(uploads_until_converged(r, s, got), 1u);
  EXPECT_GE(src->asked(), 1);
}

TEST(ErrorLodRender, AStoreWithErrorsRendersAsTheMeasuringSource) {
  const auto procedural = sphere();
  const TempDir dir;
  StoreWriteOptions w;
  w.brick_errors = true;
  w.threads = 2;
  write_brick_store(*procedural, dir.file("sphere.rbs"), w);
  const auto store = std::make_shared<const BrickStoreSource>(dir.file("sphere.rbs"));
  ASSERT_TRUE(store->stats().brick_errors);
  for (double colour : {0.125, 0.0625}) {
    Scene s = sphere_scene();
    s.lod_error_color = colour;
    Renderer measured(procedural, cpu::make_backend(1), sync(true));
    Renderer stored(store, cpu::make_backend(1), sync(true));
    Image a, b;
    EXPECT_EQ(uploads_until_converged(stored, s, b), uploads_until_converged(measured, s, a))
        << "colour error " << colour;
    EXPECT_EQ(max_diff(a, b), 0.0) << "colour error " << colour;
  }
}

}  // namespace
}  // namespace resoct::test
