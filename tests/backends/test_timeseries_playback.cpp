// Playing a time series through the whole frame loop (docs/renderer.md "Time series"): one
// renderer steps through five timepoints of a ball that moves and changes its values, and each
// converged image must be byte for byte the image of a fresh renderer opened at that timepoint,
// so nothing of an earlier timepoint -- bricks, EMPTY/HOMOGENEOUS page values, node metadata used
// for empty-space skipping -- survives a switch. Runs on the CPU backend and, in builds with
// Vulkan, on the Vulkan backend (the host side is shared), with and without prefetching of the
// next timepoint.
#include <cstring>
#include <memory>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/base/error.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
#include "support/time_series_source.hpp"
#ifdef RESOCT_TEST_VULKAN
#include "resoct/vulkan/devices.hpp"
#include "resoct/vulkan/vulkan_backend.hpp"
#include "support/vulkan_required.hpp"
#endif

namespace resoct::test {
namespace {

std::vector<std::string> playback_backends() {
#ifdef RESOCT_TEST_VULKAN
  return {"cpu", "vulkan"};
#else
  return {"cpu"};
#endif
}

Scene ball_scene() {
  Scene s;
  s.camera.eye = {1.4, 1.1, 1.7};
  s.camera.target = {0.5, 0.5, 0.5};
  s.viewport = Viewport{24, 24};
  ChannelSettings c;
  c.channel = 0;
  c.tf = TransferFunction({TfPoint{0.0, {0.0, 0.0, 0.0, 0.0}}, TfPoint{0.1, {0.2, 0.4, 1.0, 0.0}},
                           TfPoint{0.6, {1.0, 0.8, 0.2, 0.6}}, TfPoint{1.0, {1.0, 1.0, 1.0, 1.0}}});
  s.channels.push_back(c);
  return s;
}

bool same_bytes(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::memcmp(a.pixels().data(), b.pixels().data(),
                     a.pixels().size() * sizeof(a.pixels()[0])) == 0;
}

class TimeSeriesPlayback : public ::testing::TestWithParam<std::tuple<std::string, bool>> {
 protected:
  void SetUp() override {
    options_.loader_threads = 0;  // deterministic: loads happen inside render_frame
    options_.leaf_size = glm::uvec3(8);
    options_.prefetch.next_timepoint = std::get<1>(GetParam());
    if (std::get<0>(GetParam()) == "cpu") {
      cpu::register_backend();
      options_.backend = "cpu";
      options_.backend_options.threads = 1;
      return;
    }
#ifdef RESOCT_TEST_VULKAN
    if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
    vk::register_backend();
    options_.backend = "vulkan";
    options_.backend_options.validation = true;
#endif
  }

  RendererOptions options_;
};

TEST_P(TimeSeriesPlayback, EachConvergedTimepointEqualsAFreshRendererAtIt) {
  const auto series = make_moving_ball_series(5);
  Renderer player(series, options_);
  ASSERT_EQ(player.timepoints(), 5u);
  Scene scene = ball_scene();
  Image previous;
  for (std::uint32_t t = 0; t < 5; ++t) {
    SCOPED_TRACE("timepoint " + std::to_string(t));
    scene.timepoint = t;
    const ConvergeReport played = player.render_until_converged(scene, 64);
    ASSERT_TRUE(played.converged) << played.frames << " frames";
    EXPECT_EQ(played.last.stats.timepoint, t);
    EXPECT_EQ(player.timepoint(), t);

    Renderer fresh(series, options_);
    const ConvergeReport direct = fresh.render_until_converged(scene, 64);
    ASSERT_TRUE(direct.converged);
    EXPECT_TRUE(same_bytes(played.last.image, direct.last.image))
        << "the converged image after playing differs from a fresh renderer's";
    // The ball moved: consecutive timepoints really render differently.
    if (t > 0) {
      EXPECT_FALSE(same_bytes(played.last.image, previous));
    }
    previous = played.last.image;
  }
  const BrickLoaderStats ls = inspect::loader(player).stats();
  EXPECT_EQ(ls.timepoint_switches, 4u);
  if (options_.prefetch.next_timepoint) {
    EXPECT_GT(ls.prefetched, 0u);
    EXPECT_GT(ls.prefetch_hits, 0u) << "switching never used a prefetched brick";
  }
}

TEST_P(TimeSeriesPlayback, TheFrameThatSwitchesShowsNothingOfThePreviousTimepoint) {
  const auto series = make_moving_ball_series(5);
  Renderer player(series, options_);
  Scene scene = ball_scene();
  ASSERT_TRUE(player.render_until_converged(scene, 64).converged);
  // Jumping from 0 to 4 (no shared voxels: the ball moved by 16): every brick, page value and node
  // summary is invalidated, so the switching frame has nothing resident and renders background,
  // exactly like the first frame of a fresh renderer at timepoint 4.
  scene.timepoint = 4;
  const FrameReport first = player.render_frame(scene);
  EXPECT_TRUE(first.stats.timepoint_switched);
  EXPECT_EQ(inspect::cache(player).resident_count(), 0u);
  Renderer fresh(series, options_);
  const FrameReport fresh_first = fresh.render_frame(scene);
  EXPECT_TRUE(same_bytes(first.image, fresh_first.image));
  // And back again: the old timepoint's host-cached bricks serve it, still converging exactly.
  scene.timepoint = 0;
  const ConvergeReport back = player.render_until_converged(scene, 64);
  ASSERT_TRUE(back.converged);
  scene.timepoint = 0;
  Renderer fresh0(series, options_);
  EXPECT_TRUE(same_bytes(back.last.image, fresh0.render_until_converged(scene, 64).last.image));
}

TEST_P(TimeSeriesPlayback, ASceneWithoutATimepointShowsTheOneTheSourceWasOpenedAt) {
  const auto opened_at_2 = make_moving_ball_series(5, 2);
  Renderer r(opened_at_2, options_);
  EXPECT_EQ(r.timepoint(), 2u);
  Scene scene = ball_scene();  // no timepoint
  const ConvergeReport own = r.render_until_converged(scene, 64);
  ASSERT_TRUE(own.converged);
  EXPECT_EQ(own.last.stats.timepoint, 2u);
  EXPECT_EQ(inspect::loader(r).stats().timepoint_switches, 0u);
  scene.timepoint = 2;
  Renderer from_0(make_moving_ball_series(5), options_);
  EXPECT_TRUE(same_bytes(own.last.image, from_0.render_until_converged(scene, 64).last.image));
}

TEST_P(TimeSeriesPlayback, ATimepointPastTheSeriesNamesTheField) {
  const auto series = make_moving_ball_series(5);
  Renderer player(series, options_);
  Scene scene = ball_scene();
  scene.timepoint = 5;
  try {
    player.render_frame(scene);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("timepoint"), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, TimeSeriesPlayback,
                         ::testing::Combine(::testing::ValuesIn(playback_backends()),
                                            ::testing::Bool()),
                         [](const auto& param_info) {
                           return std::get<0>(param_info.param) +
                                  (std::get<1>(param_info.param) ? "_prefetch" : "_noprefetch");
                         });

}  // namespace
}  // namespace resoct::test
