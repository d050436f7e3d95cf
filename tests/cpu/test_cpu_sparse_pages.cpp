// The sparse page table in the whole frame loop with the CPU backend: the first frame of a cold
// cache only reports block misses (no block is allocated yet), the next frame requests bricks in
// the allocated blocks, and the run converges to the image of the fully resident scene; a pool
// smaller than the table's blocks is reclaimed while the view moves and still converges to the
// image of a run whose pool holds every block; and a
// 65536^3 volume (2^33 bricks at level 0) converges at a distant view with a bounded pool.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <memory>
#include <string>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"
#include "support/resident_scene.hpp"

using namespace resoct;

namespace {

RendererOptions options(glm::uvec3 leaf) {
  cpu::register_backend();
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.loader_threads = 0;  // deterministic
  o.leaf_size = leaf;
  return o;
}

Scene scene_for(std::uint32_t size, glm::dvec3 eye) {
  Scene s = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
  s.viewport = Viewport{size, size};
  s.camera.eye = eye;
  return s;
}

// Renders `scene` with everything resident (the reference of a converged frame).
Image resident_image(const BrickSource& source, const Scene& scene, glm::uvec3 leaf) {
  test::ResidentOptions ro;
  ro.leaf_size = leaf;
  const test::ResidentScene resident(source, {0}, ro);
  cpu::CpuBackend backend(1);
  resident.upload(backend);
  FrameResult full;
  FrameOptions fo;
  fo.mode = RenderMode::residency;
  backend.render(resident.tables(scene, fo), full);
  return std::move(full.image);
}

void expect_same_image(const Image& a, const Image& b) {
  const ImageDiff d = compare_images(a, b);
  for (int ch = 0; ch < 4; ++ch) EXPECT_LE(d.max_abs[ch], 2e-3) << "channel " << ch;
}

TEST(CpuSparsePages, BlockMissesFirstThenBricksThenTheResidentImage) {
  // 4^3 bricks: level 0 is 32^3 bricks, 2^3 blocks.
  std::shared_ptr<const BrickSource> source =
      make_procedural_source("procedural:sphere:128x128x128", BrickLayout{glm::uvec3(4), 1});
  const Scene scene = scene_for(40, {1.6, 1.3, 1.9});
  Renderer r(source, options(glm::uvec3(8)));
  EXPECT_EQ(inspect::page_table(r).allocated_blocks(), 0u);

  const FrameReport f1 = r.render_frame(scene);
  EXPECT_FALSE(f1.converged);
  EXPECT_GT(f1.stats.block_misses, 0u);
  // Nothing is allocated yet, so every brick request is a block miss.
  EXPECT_EQ(f1.stats.brick_requests, f1.stats.block_misses);
  EXPECT_EQ(f1.stats.bricks_uploaded, 0u);
  EXPECT_EQ(f1.stats.page_blocks, 0u);

  const FrameReport f2 = r.render_frame(scene);
  EXPECT_FALSE(f2.converged);
  // The blocks reported in frame 1 were allocated at the start of frame 2.
  EXPECT_GE(f2.stats.page_blocks, f1.stats.block_misses);
  EXPECT_GT(f2.stats.brick_requests, f2.stats.block_misses);

  std::uint32_t frames = 2;
  FrameReport last = f2;
  while (!last.converged && frames < 64) {
    last = r.render_frame(scene);
    ++frames;
  }
  ASSERT_TRUE(last.converged) << frames << " frames";
  EXPECT_EQ(last.stats.block_misses, 0u);
  EXPECT_EQ(last.stats.backend.cap_hits, 0u);
  EXPECT_LE(inspect::page_table(r).allocated_blocks(), inspect::page_table(r).max_blocks());
  expect_same_image(last.image, resident_image(*source, scene, glm::uvec3(8)));
}

TEST(CpuSparsePages, SmallPoolIsReclaimedWhileTheViewMovesAndStillConverges) {
  // 4^3 bricks over 512^3: level 0 is 128^3 bricks in 8^3 blocks, 589 blocks over all levels.
  std::shared_ptr<const BrickSource> source =
      make_procedural_source("procedural:sphere:512x512x512", BrickLayout{glm::uvec3(4), 1});
  RendererOptions o = options(glm::uvec3(16));
  const std::uint64_t slot_bytes =
      source->hierarchy().layout().padded_voxels() * voxel_size(source->volume().type);
  o.device_cache_bytes = 16 * slot_bytes;
  // The orbit below touches about 23 blocks, so a pool just above the 16 cache slots must reclaim.
  o.page_pool_blocks = 17;
  ASSERT_EQ(PageTable::block_count(source->hierarchy(), 1), 589u);
  Renderer r(source, o);
  std::uint32_t full_pool_frames = 0;
  std::vector<std::uint32_t> last_dir = inspect::page_table(r).directory();
  std::uint64_t freed = 0;  // directory entries that went from allocated back to 0
  for (int i = 0; i < 24; ++i) {
    const double a = 0.5 * i;
    const FrameReport f =
        r.render_frame(scene_for(16, {0.5 + 0.7 * std::cos(a), 0.5 + 0.7 * std::sin(a), 0.55}));
    ASSERT_EQ(f.stats.backend.cap_hits, 0u);
    const auto& dir = inspect::page_table(r).directory();
    for (std::size_t d = 0; d < dir.size(); ++d) freed += last_dir[d] != 0 && dir[d] == 0 ? 1 : 0;
    last_dir = dir;
    full_pool_frames += inspect::page_table(r).allocated_blocks() == o.page_pool_blocks ? 1 : 0;
  }
  EXPECT_GT(full_pool_frames, 0u);
  EXPECT_GT(freed, 0u) << "the pool was never reclaimed";
  const Scene still = scene_for(8, {1.6, 1.3, 1.9});  // a working set within the 16 slots
  const ConvergeReport rep = r.render_until_converged(still, 64);
  ASSERT_TRUE(rep.converged) << rep.frames << " frames";
  // The same still view from a cold cache with a pool holding every block (never reclaimed);
  // loading all 2.4 M bricks for a resident reference would take minutes.
  RendererOptions big = o;
  big.page_pool_blocks = 0;
  big.device_cache_bytes = std::uint64_t(64) << 20;
  Renderer ref(source, big);
  const ConvergeReport ref_rep = ref.render_until_converged(still, 64);
  ASSERT_TRUE(ref_rep.converged);
  EXPECT_EQ(inspect::page_table(ref).max_blocks(), 589u);
  expect_same_image(rep.last.image, ref_rep.last.image);
}

TEST(CpuSparsePages, Volume65536CubedConvergesAtADistantViewWithABoundedPool) {
  BrickLayout layout;
  layout.brick_size = glm::uvec3(32);
  // One field sample per coarse voxel (as bench_scaling): coarse bricks stay cheap to build.
  auto source =
      std::make_shared<ProceduralSource>("procedural:tubes:65536x65536x65536:1", layout, 0);
  ASSERT_EQ(source->hierarchy().level(0).brick_count, std::uint64_t(1) << 33);
  RendererOptions o = options(glm::uvec3(2048));
  o.strategy = RequestStrategy::global;
  o.upload_budget.max_bricks = 1024;
  o.device_cache_bytes = std::uint64_t(64) << 20;  // 1707 slots of 34^3 bytes
  o.page_pool_blocks = 2048;
  Renderer r(source, o);
  Scene s;
  s.camera.eye = {1.8, 1.4, 2.2};
  s.camera.target = {0.5, 0.5, 0.5};
  s.viewport = {32, 32};
  ChannelSettings ch;
  ch.channel = 0;
  ch.tf = TransferFunction({{0.0, {1, 1, 1, 0}}, {0.1, {1, 1, 1, 0}}, {1.0, {1.0, 0.8, 0.6, 0.3}}});
  s.channels.push_back(ch);
  const ConvergeReport rep = r.render_until_converged(s, 12);
  ASSERT_TRUE(rep.converged) << rep.frames << " frames";
  EXPECT_EQ(rep.last.stats.backend.cap_hits, 0u);
  EXPECT_GT(rep.last.stats.working_set_bricks, 0u);
  EXPECT_LE(inspect::page_table(r).allocated_blocks(), 2048u);
  // Host memory: the directory (about 2.4 M words) and the blocks in use, nothing per brick.
  EXPECT_LT(inspect::page_table(r).directory().size(), 3'000'000u);
  EXPECT_LE(inspect::page_table(r).pool().size(), (2048u + 1u) * 4096u);
  std::size_t shown = 0;
  for (const glm::vec4& px : rep.last.image.pixels()) shown += px.a > 0.01f ? 1u : 0u;
  EXPECT_GT(shown, 0u);
}

TEST(CpuSparsePages, PoolSizeIsCheckedAtConstruction) {
  std::shared_ptr<const BrickSource> source =
      make_procedural_source("procedural:sphere:512x512x512", BrickLayout{glm::uvec3(4), 1});
  RendererOptions o = options(glm::uvec3(16));
  const std::uint64_t slot_bytes =
      source->hierarchy().layout().padded_voxels() * voxel_size(source->volume().type);
  o.device_cache_bytes = 100 * slot_bytes;
  // Not more blocks than cache slots (and fewer than the 589 blocks): no victim guaranteed.
  o.page_pool_blocks = 100;
  EXPECT_RESOCT_ERROR(Renderer(source, o), ErrorCode::invalid_argument, "page_pool_blocks");
  o.page_pool_blocks = kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS;
  EXPECT_RESOCT_ERROR(Renderer(source, o), ErrorCode::invalid_argument, "page_pool_blocks");
  // A pool covering every block needs no headroom; the default is clamped to the blocks.
  o.device_cache_bytes = 1000 * slot_bytes;
  o.page_pool_blocks = 589;
  EXPECT_EQ(inspect::page_table(Renderer(source, o)).max_blocks(), 589u);
  o.page_pool_blocks = 0;
  EXPECT_EQ(inspect::page_table(Renderer(source, o)).max_blocks(), 589u);
  o.device_cache_bytes = 100 * slot_bytes;
  EXPECT_EQ(inspect::page_table(Renderer(source, o)).max_blocks(), 164u);  // 100 + max(50, 64)
}

}  // namespace
