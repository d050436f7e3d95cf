// A PyramidSource with lazy region metadata (coarse nodes first answered "unknown", fine ones
// exactly) renders to the same converged image as the same volume with eagerly scanned
// metadata: lazy answers only delay empty-space skipping, they never hide voxels.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/scene/scene.hpp"

using namespace resoct;

namespace {

/// A few soft blobs in empty space (so that skipping matters), u8.
DenseVolume blobs(std::uint32_t n) {
  VolumeDesc d;
  d.extent = glm::u64vec3(n);
  d.type = VoxelType::u8;
  std::mt19937 rng(21);
  std::vector<glm::dvec4> centers;  // xyz, radius
  for (int i = 0; i < 6; ++i) {
    centers.emplace_back(double(rng() % n), double(rng() % n), double(rng() % n),
                         4.0 + double(rng() % 8));
  }
  std::vector<std::uint8_t> v(std::size_t(n) * n * n, 0);
  for (std::uint32_t z = 0; z < n; ++z) {
    for (std::uint32_t y = 0; y < n; ++y) {
      for (std::uint32_t x = 0; x < n; ++x) {
        double s = 0.0;
        for (const glm::dvec4& c : centers) {
          const double r = glm::length(glm::dvec3(x, y, z) - glm::dvec3(c));
          s = std::max(s, 1.0 - r / c.w);
        }
        v[(std::size_t(z) * n + y) * n + x] = std::uint8_t(std::lround(255.0 * s));
      }
    }
  }
  return DenseVolume::from_values(d, v);
}

TEST(LazyMetadataRender, ConvergesToTheEagerImage) {
  cpu::register_backend();
  const DenseVolume volume = blobs(48);
  const BrickLayout layout{glm::uvec3(8), 1};
  PyramidSourceOptions eager_options;
  eager_options.metadata_block = 4;
  eager_options.threads = 1;
  PyramidSourceOptions lazy_options = eager_options;
  lazy_options.eager_scan_voxels = 0;
  // Leaf nodes (8 voxels plus a margin: 27 blocks of 4) are computed exactly; wider nodes are
  // "unknown" until their blocks are cached.
  lazy_options.lazy_query_blocks = 27;
  std::shared_ptr<const PyramidSource> eager =
      make_dense_pyramid_source(volume, layout, "eager", eager_options);
  std::shared_ptr<const PyramidSource> lazy =
      make_dense_pyramid_source(volume, layout, "lazy", lazy_options);
  ASSERT_TRUE(lazy->lazy_metadata());

  Scene scene = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
  scene.viewport = Viewport{40, 40};
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.loader_threads = 0;  // deterministic
  o.leaf_size = glm::uvec3(8);

  Renderer eager_renderer(eager, o);
  Renderer lazy_renderer(lazy, o);
  const ConvergeReport e = eager_renderer.render_until_converged(scene, 64);
  const ConvergeReport l = lazy_renderer.render_until_converged(scene, 64);
  ASSERT_TRUE(e.converged);
  ASSERT_TRUE(l.converged) << "after " << l.frames << " frames";
  EXPECT_GT(lazy->lazy_blocks_computed(), 0u);

  std::size_t shown = 0;
  const glm::vec4 bg(scene.background);
  for (const glm::vec4& px : e.last.image.pixels()) {
    shown += glm::length(px - bg) > 0.02f;
  }
  EXPECT_GT(shown, e.last.image.pixels().size() / 50) << "the view shows too little";
  const ImageDiff d = compare_images(l.last.image, e.last.image);
  for (int ch = 0; ch < 4; ++ch) EXPECT_LE(d.max_abs[ch], 2e-3) << "channel " << ch;
}

}  // namespace
