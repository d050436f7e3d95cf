// The renderer under pressure: a device cache smaller than the working set, channel remaps while
// loads are in flight, and bricks that fail to load.
#include "core/render/test_renderer_support.hpp"

#include <random>

namespace resoct::test {
namespace {

/// Runs `frames` frames with a cache of `cache_slots` (< the 32 varying level-0 bricks plus
/// ancestors the scene needs) and checks pinning, progress and coverage.
void run_small_cache(std::uint32_t ttl, std::string_view eviction) {
  auto src = make_test_source();
  RendererOptions o = test_options(12, 256);
  o.ttl = ttl;
  o.eviction = parse_eviction(eviction);
  Rig rig(src, o);
  const Scene scene = test_scene(0);
  std::map<std::uint32_t, std::uint64_t> uploaded_at;  // cache slot -> frame of its last upload
  std::set<BrickKey> ever_mapped;
  std::vector<std::uint64_t> uploads_per_frame;
  constexpr std::uint64_t kFrames = 40;
  for (std::uint64_t f = 1; f <= kFrames; ++f) {
    const FrameReport rep = rig.renderer->render_frame(scene);
    EXPECT_FALSE(rep.converged);  // the working set never fits
    const RecordedUpdate& u = rig.backend->updates().back();
    for (std::uint32_t s : u.upload_slots) {
      auto it = uploaded_at.find(s);
      // Overwriting a slot evicts its brick: never before it was pinned for ttl frames.
      if (it != uploaded_at.end()) {
        EXPECT_GE(f, it->second + ttl) << "slot " << s;
      }
      uploaded_at[s] = f;
    }
    uploads_per_frame.push_back(u.upload_slots.size());
    ASSERT_EQ(check_state(*rig.renderer, *rig.backend, *src), "") << "frame " << f;
    for (const PageAddress& a : level0_bricks(rig.renderer->hierarchy(), 0)) {
      if (kernel::resoct_page_is_mapped(inspect::page_table(*rig.renderer).entry(a))) {
        ever_mapped.insert(BrickKey(0, 0, a.brick));
      }
    }
  }
  // Progress: after the first frame (block misses: the page-table blocks are allocated) and
  // the first request round trip, every window of ttl frames uploads bricks.
  for (std::size_t f = 2; f + ttl <= uploads_per_frame.size(); ++f) {
    std::uint64_t sum = 0;
    for (std::size_t k = 0; k < ttl; ++k) sum += uploads_per_frame[f + k];
    EXPECT_GT(sum, 0u) << "no upload in frames " << f + 1 << ".." << f + ttl;
  }
  // Requests beyond the capacity are served over successive frames: every varying level-0
  // brick was on the device at some point.
  EXPECT_EQ(ever_mapped.size(), 32u);
}

TEST(RendererProgress, SmallCacheProgressesEveryFrameWithTtl1) {
  run_small_cache(1, "lru");
}
TEST(RendererProgress, SmallCacheProgressesEveryTtlFramesWithTtl2) {
  run_small_cache(2, "lru");
}
TEST(RendererProgress, SmallCacheWithOctreemizerEviction) {
  run_small_cache(2, "octreemizer");
}
TEST(RendererProgress, SmallCacheWithOctreemizerCameraEviction) {
  run_small_cache(2, "octreemizer-camera");
}

TEST(RendererProgress, ConvergeTerminatesAtTheCap) {
  auto src = make_test_source();
  Rig rig(src, test_options(12, 256));
  const ConvergeReport rep = rig.renderer->render_until_converged(test_scene(0), 25);
  EXPECT_FALSE(rep.converged);
  EXPECT_EQ(rep.frames, 25u);
  EXPECT_EQ(rig.renderer->frame_index(), 25u);
}

TEST(RendererProgress, RemapDropsBricksLoadedForTheOldChannel) {
  auto src = make_test_source();
  Rig rig(src, test_options(64, 4));
  for (int f = 0; f < 3; ++f) rig.renderer->render_frame(test_scene(0));
  // Frame 3 requested more channel-0 bricks and (synchronously) loaded them; channel 1 now takes
  // the only slot, so they must be dropped, not uploaded.
  ASSERT_GT(inspect::loader(*rig.renderer).ready(), 0u);
  const std::uint64_t epoch = inspect::channel_map(*rig.renderer).epoch();
  const FrameReport rep = rig.renderer->render_frame(test_scene(1));
  EXPECT_GT(rep.stats.stale_loads, 0u);
  EXPECT_GT(inspect::channel_map(*rig.renderer).epoch(), epoch);
  EXPECT_EQ(inspect::channel_map(*rig.renderer).channel(0), 1u);
  ASSERT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
  const ConvergeReport c1 = rig.renderer->render_until_converged(test_scene(1), 100);
  ASSERT_TRUE(c1.converged);
  ASSERT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
  // Back to channel 0: its bricks come from the host cache.
  const std::uint64_t hits = inspect::loader(*rig.renderer).stats().host_hits;
  const ConvergeReport c0 = rig.renderer->render_until_converged(test_scene(0), 100);
  ASSERT_TRUE(c0.converged);
  EXPECT_GT(inspect::loader(*rig.renderer).stats().host_hits, hits);
  EXPECT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
}

TEST(RendererProgress, RandomRemapsKeepTheDeviceMirrorExact) {
  auto src = make_test_source();
  RendererOptions o = test_options(20, 6);
  o.visible_slots = 2;
  Rig rig(src, o);
  std::mt19937 rng(99);
  for (int f = 0; f < 40; ++f) {
    // One visible channel, chosen at random; the other slot keeps its old one (lazily).
    rig.renderer->render_frame(test_scene(std::uint32_t(rng() % 3)));
    ASSERT_EQ(check_state(*rig.renderer, *rig.backend, *src), "") << "frame " << f;
  }
}

TEST(RendererProgress, FailedBricksAreReportedOnceAndRenderingGoesOn) {
  auto inner = make_test_source();
  const BrickKey bad1(0, 0, {1, 2, 3}), bad2(0, 0, {2, 0, 1});
  auto src = std::make_shared<CountingSource>(inner, std::set<BrickKey>{bad1, bad2});
  Rig rig(src, test_options(256, 256));
  std::vector<LoadFailure> seen;
  rig.renderer->set_failure_callback([&](const LoadFailure& f) { seen.push_back(f); });
  const ConvergeReport rep = rig.renderer->render_until_converged(test_scene(0), 50);
  EXPECT_TRUE(rep.converged);
  ASSERT_EQ(seen.size(), 2u);
  ASSERT_EQ(rep.last.failures.size(), 2u);
  for (const LoadFailure& f : seen) {
    EXPECT_TRUE(f.key == bad1 || f.key == bad2);
    EXPECT_NE(f.message.find("counting-source"), std::string::npos) << f.message;
    EXPECT_NE(f.message.find("injected failure"), std::string::npos) << f.message;
  }
  for (int f = 0; f < 5; ++f) {
    const FrameReport more = rig.renderer->render_frame(test_scene(0));
    EXPECT_TRUE(more.converged);
    EXPECT_TRUE(more.failures.empty());
    EXPECT_EQ(more.stats.failed_requests, 2u);  // still asked for by the kernel, ignored
  }
  EXPECT_EQ(src->reads(bad1), 1);
  EXPECT_EQ(src->reads(bad2), 1);
  EXPECT_EQ(seen.size(), 2u);
  const auto& pt = inspect::page_table(*rig.renderer);
  EXPECT_EQ(pt.entry(PageAddress{0, 0, bad1.brick()}), kernel::RESOCT_PAGE_UNMAPPED_WORD);
  EXPECT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
}

TEST(RendererProgress, LoaderThreadsConvergeToTheSameState) {
  auto src = make_test_source();
  RendererOptions o = test_options(256, 8);
  o.loader_threads = 3;
  Rig rig(src, o);
  const ConvergeReport rep = rig.renderer->render_until_converged(test_scene(2), 200);
  ASSERT_TRUE(rep.converged);
  EXPECT_EQ(check_state(*rig.renderer, *rig.backend, *src), "");
  for (const PageAddress& a : level0_bricks(rig.renderer->hierarchy(), 0)) {
    EXPECT_NE(inspect::page_table(*rig.renderer).entry(a), kernel::RESOCT_PAGE_UNMAPPED_WORD);
  }
}

}  // namespace
}  // namespace resoct::test
