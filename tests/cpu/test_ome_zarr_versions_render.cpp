// The same image written as OME-Zarr 0.4 (zarr-python, zarr v2, zstd chunks) and as 0.5 (Zarr v3,
// blosc-compressed inner chunks in shards) renders to the same converged image: the reader, not
// the container, decides what the renderer sees. (tests/data/make_ome_zarr_v3.py writes the pair;
// test_formats_ome_zarr_v3 compares their bricks.)
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <memory>
#include <string>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/scene/scene.hpp"
#include "support/generated_data.hpp"

using namespace resoct;

namespace {

TEST(OmeZarrVersionsRender, The04And05CopiesOfAnImageRenderIdentically) {
  cpu::register_backend();
  const std::string dir =
      test::python_generated_dir(RESOCT_BINARY_DIR "/test-data", "ome-zarr-v3",
                                 RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr_v3.py");
  ASSERT_FALSE(dir.empty());
  const BrickLayout layout{glm::uvec3(8), 1};
  std::shared_ptr<const BrickSource> v04 = open_source(dir + "/pair_v04.zarr", layout);
  std::shared_ptr<const BrickSource> v05 = open_source(dir + "/pair_v05.zarr", layout);
  ASSERT_EQ(v04->volume(), v05->volume());

  Scene scene = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
  scene.viewport = Viewport{48, 40};
  scene.channels.push_back(scene.channels.front());
  scene.channels.back().channel = 1;  // both channels of the pair
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.loader_threads = 0;  // deterministic
  o.leaf_size = glm::uvec3(8);
  Renderer r04(v04, o);
  Renderer r05(v05, o);
  const ConvergeReport a = r04.render_until_converged(scene, 64);
  const ConvergeReport b = r05.render_until_converged(scene, 64);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_EQ(a.frames, b.frames);

  std::size_t shown = 0;
  const glm::vec4 bg(scene.background);
  for (const glm::vec4& px : a.last.image.pixels()) shown += glm::length(px - bg) > 0.02f;
  EXPECT_GT(shown, a.last.image.pixels().size() / 20) << "the view shows too little";
  const ImageDiff d = compare_images(a.last.image, b.last.image);
  for (int ch = 0; ch < 4; ++ch) EXPECT_EQ(d.max_abs[ch], 0.0f) << "channel " << ch;
}

}  // namespace
