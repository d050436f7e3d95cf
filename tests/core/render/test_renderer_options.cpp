// The Renderer's options: the names of every choice parse back to their enum and an unknown name
// is an error naming the parameter and the accepted names; each layer validates its own fields;
// and an unregistered backend name says how to get a backend.
#include <gtest/gtest.h>

#include "resoct/backend/backend.hpp"
#include "resoct/render/renderer_options.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

TEST(RendererOptions, ChoiceNamesRoundTrip) {
  for (const auto s : {RequestStrategy::greedy, RequestStrategy::global}) {
    EXPECT_EQ(parse_request_strategy(to_string(s)), s);
  }
  for (const auto e : {Eviction::lru, Eviction::octreemizer, Eviction::octreemizer_camera}) {
    EXPECT_EQ(parse_eviction(to_string(e)), e);
  }
  for (const auto o :
       {FrameOutput::rgba32f, FrameOutput::rgba8, FrameOutput::both, FrameOutput::device}) {
    EXPECT_EQ(parse_frame_output(to_string(o)), o);
  }
  for (const auto m : {RenderMode::residency, RenderMode::pagetable, RenderMode::octree}) {
    EXPECT_EQ(parse_render_mode(to_string(m)), m);
  }
  EXPECT_STREQ(to_string(RequestStrategy::global), "global");
  EXPECT_STREQ(to_string(Eviction::octreemizer_camera), "octreemizer-camera");
  EXPECT_STREQ(to_string(static_cast<Eviction>(9)), "unknown");
}

TEST(RendererOptions, UnknownNamesNameTheParameterAndTheChoices) {
  EXPECT_RESOCT_ERROR(parse_request_strategy("lazy"), ErrorCode::invalid_argument,
                      "parameter 'strategy': 'lazy' is not one of greedy, global");
  EXPECT_RESOCT_ERROR(parse_request_strategy("lazy", "--strategy"), ErrorCode::invalid_argument,
                      "parameter '--strategy'");
  EXPECT_RESOCT_ERROR(parse_eviction("fifo"), ErrorCode::invalid_argument,
                      "parameter 'eviction': 'fifo' is not one of lru, octreemizer, "
                      "octreemizer-camera");
  EXPECT_RESOCT_ERROR(parse_frame_output("rgb"), ErrorCode::invalid_argument,
                      "parameter 'output': 'rgb' is not one of rgba32f, rgba8, both");
  EXPECT_RESOCT_ERROR(parse_render_mode("ray"), ErrorCode::invalid_argument,
                      "'ray' is not one of residency, pagetable, octree");
}

TEST(RendererOptions, EachLayerNamesItsBadField) {
  ViewerOptions v;
  v.loader_threads = 2000;
  EXPECT_RESOCT_ERROR(v.validate(), ErrorCode::invalid_argument, "loader_threads");
  v = ViewerOptions{};
  v.output = static_cast<FrameOutput>(5);
  EXPECT_RESOCT_ERROR(v.validate(), ErrorCode::invalid_argument, "output");
  v = ViewerOptions{};
  v.strategy = static_cast<RequestStrategy>(5);
  EXPECT_RESOCT_ERROR(RendererOptions(v).validate(), ErrorCode::invalid_argument, "strategy");

  TuningOptions t;
  t.max_node_answers = 0;
  EXPECT_RESOCT_ERROR(t.validate(), ErrorCode::invalid_argument, "max_node_answers");
  EXPECT_RESOCT_ERROR(RendererOptions(ViewerOptions{}, t).validate(), ErrorCode::invalid_argument,
                      "max_node_answers");

  RendererOptions o;
  o.backend.clear();
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "backend");
  EXPECT_NO_THROW(RendererOptions().validate());
}

TEST(RendererOptions, UnregisteredBackendSaysHowToGetOne) {
  EXPECT_RESOCT_ERROR(create_backend("no-such-backend"), ErrorCode::invalid_argument,
                      "pass a backend object to the Renderer");
}

}  // namespace
}  // namespace resoct::test
