// Rendering a brick store over HTTP (loopback server, Range requests) gives exactly the image of
// rendering the same store from the local file, frame by frame, with the same convergence.
#include <gtest/gtest.h>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
#include "support/http_test_server.hpp"

using namespace resoct;

TEST(HttpRender, ImagesEqualTheLocalStoreFrameByFrame) {
  test::TempDir dir;
  const auto src =
      make_procedural_source("procedural:tubes:64x64x64", BrickLayout{glm::uvec3(8), 1});
  write_brick_store(*src, dir.file("tubes.rbs"));
  test::HttpTestServer server(test::HttpTestServer::default_script(), dir.path().string());

  Scene scene = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/tubes.json");
  scene.viewport = Viewport{28, 28};
  cpu::register_backend();
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.loader_threads = 0;  // deterministic: both renderers load the same bricks in the same frames
  o.leaf_size = glm::uvec3(8);

  Renderer local(std::make_shared<BrickStoreSource>(dir.file("tubes.rbs")), o);
  Renderer remote(open_source(server.base("ok") + "/tubes.rbs"), o);
  bool converged = false;
  int frames = 0;
  for (; frames < 32 && !converged; ++frames) {
    const FrameReport a = local.render_frame(scene);
    const FrameReport b = remote.render_frame(scene);
    ASSERT_EQ(a.converged, b.converged) << "frame " << frames;
    ASSERT_EQ(a.stats.bricks_uploaded, b.stats.bricks_uploaded) << "frame " << frames;
    ASSERT_TRUE(b.failures.empty());
    ASSERT_EQ(a.image.pixels().size(), b.image.pixels().size());
    for (std::size_t i = 0; i < a.image.pixels().size(); ++i) {
      ASSERT_EQ(a.image.pixels()[i], b.image.pixels()[i]) << "frame " << frames << " pixel " << i;
    }
    converged = a.converged;
  }
  EXPECT_TRUE(converged);
  EXPECT_GT(frames, 1);
  EXPECT_GT(inspect::loader(remote).stats().loads, 0u);
}
