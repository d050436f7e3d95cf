// Prefetching with the real CPU backend: the conservative view enumeration contains every brick
// the traversal requests for that view, and prefetching changes no image (it fills only the host
// cache) while later requests hit what it loaded.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <glm/geometric.hpp>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/base/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/engine/prefetch.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

Scene tubes_scene(std::uint32_t size) {
  Scene s = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/tubes.json");
  s.viewport = Viewport{size, size};
  return s;
}

RendererOptions sync_options() {
  cpu::register_backend();
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.loader_threads = 0;
  o.leaf_size = glm::uvec3(8);
  return o;
}

}  // namespace

TEST(PrefetchRender, EnumerationContainsEveryBrickTheTraversalRequests) {
  std::shared_ptr<const BrickSource> src =
      make_procedural_source("procedural:tubes:64x64x64", BrickLayout{glm::uvec3(8), 1});
  for (const double lod_px : {1.0, 3.0}) {
    Scene scene = tubes_scene(36);
    scene.lod_error_px = lod_px;
    RendererOptions o = sync_options();
    o.strategy = RequestStrategy::global;  // only the bricks the samples need, no ancestors
    Renderer r(src, o);
    const ConvergeReport rep = r.render_until_converged(scene, 64);
    ASSERT_TRUE(rep.converged);
    const auto listed = view_bricks(src->hierarchy(), scene, 1u << 20);
    const std::set<BrickKey> set(listed.begin(), listed.end());
    std::size_t loaded = 0;
    const BrickHierarchy& h = src->hierarchy();
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const glm::uvec3 n = h.level(l).bricks;
      for (std::uint32_t z = 0; z < n.z; ++z) {
        for (std::uint32_t y = 0; y < n.y; ++y) {
          for (std::uint32_t x = 0; x < n.x; ++x) {
            const std::uint32_t e = inspect::page_table(r).entry(PageAddress{0, l, {x, y, z}});
            if (kernel::resoct_page_state(e) == kernel::RESOCT_PAGE_STATE_UNMAPPED) continue;
            ++loaded;
            EXPECT_TRUE(set.count(BrickKey(l, 0, {x, y, z})))
                << "lod " << lod_px << ": level " << l << " brick " << x << "," << y << "," << z;
          }
        }
      }
    }
    EXPECT_GT(loaded, 4u);
  }
}

TEST(PrefetchRender, ChangesNoImageAndServesLaterRequests) {
  std::shared_ptr<const BrickSource> src =
      make_procedural_source("procedural:tubes:64x64x64", BrickLayout{glm::uvec3(8), 1});
  // A narrow view that shows part of the volume, so that turning reveals bricks the current
  // view does not demand yet.
  Scene base = tubes_scene(24);
  base.camera.fov_deg = 12.0;
  RendererOptions plain = sync_options();
  plain.upload_budget.max_bricks = 6;  // several frames per pose: the path outruns the loads
  RendererOptions ahead = plain;
  ahead.prefetch.lookahead_frames = 3;
  ahead.prefetch.max_bricks = 16;
  Renderer a(src, plain), b(src, ahead);
  std::uint64_t queued = 0;
  for (int f = 0; f < 24; ++f) {
    Scene s = base;
    s.camera = orbit(base.camera, 6.0 * f);
    const FrameReport ra = a.render_frame(s);
    const FrameReport rb = b.render_frame(s);
    queued += rb.stats.prefetch_queued;
    EXPECT_EQ(ra.stats.prefetch_queued, 0u);
    ASSERT_EQ(ra.stats.bricks_uploaded, rb.stats.bricks_uploaded) << "frame " << f;
    ASSERT_EQ(ra.image.pixels(), rb.image.pixels()) << "frame " << f;
  }
  EXPECT_GT(queued, 0u);
  EXPECT_GT(inspect::loader(b).stats().prefetched, 0u);
  EXPECT_GT(inspect::loader(b).stats().prefetch_hits, 0u);
  EXPECT_EQ(inspect::loader(a).stats().prefetched, 0u);
}

TEST(PrefetchRender, OptionsAreValidated) {
  RendererOptions o = sync_options();
  o.prefetch.lookahead_frames = 65;
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "prefetch.lookahead_frames");
  o.prefetch.lookahead_frames = 2;
  o.prefetch.max_bricks = 0;
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "prefetch");
  o = sync_options();
  EXPECT_RESOCT_ERROR(parse_eviction("fifo", "host_eviction"), ErrorCode::invalid_argument,
                      "host_eviction");
  o.host_eviction = static_cast<Eviction>(7);  // what a bad cast from an integer gives
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "host_eviction");
  o.host_eviction = parse_eviction("octreemizer", "host_eviction");
  std::shared_ptr<const BrickSource> src = make_procedural_source("procedural:sphere:32x32x32");
  Renderer r(src, o);
  EXPECT_EQ(inspect::loader(r).stats().loads, 0u);
  const ConvergeReport rep = r.render_until_converged(tubes_scene(16), 32);
  EXPECT_TRUE(rep.converged);
}
