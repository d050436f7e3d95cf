// The frame loop's prefetching with loader threads and the Octreemizer host cache policy: a
// moving camera queues bricks of the predicted views, they land in the host cache only (nothing
// reaches the device unless requested), the host cache stays within its budget, and a camera at
// rest prefetches nothing.
#include <gtest/gtest.h>

#include "core/render/test_renderer_support.hpp"

namespace resoct {
namespace {

TEST(RendererPrefetch, MovingCameraFillsTheHostCacheOnly) {
  test::register_test_backend();
  auto src = test::make_test_source(1);
  RendererOptions o = test::test_options(16, 64);
  o.loader_threads = 2;
  o.host_eviction = Eviction::octreemizer;
  o.host_cache_bytes = 24 * (1000 + HostBrickCache::kEntryOverhead);  // room for 24 bricks
  o.prefetch.lookahead_frames = 3;
  o.prefetch.max_bricks = 16;
  Renderer r(src, o);
  Scene s = test::test_scene(0);
  std::uint64_t queued = 0;
  for (int f = 0; f < 12; ++f) {
    s.camera.eye = glm::dvec3(2.0 - 0.1 * f, 0.5, 0.5 + 0.08 * f);
    const FrameReport rep = r.render_frame(s);  // the recording backend requests nothing
    queued += rep.stats.prefetch_queued;
    EXPECT_EQ(rep.stats.bricks_uploaded, 0u);
    EXPECT_TRUE(rep.failures.empty());
    r.wait_for_loads();
    EXPECT_LE(inspect::loader(r).stats().prefetched, queued);
  }
  EXPECT_GT(queued, 0u);
  EXPECT_GT(inspect::loader(r).stats().prefetched, 0u);
  EXPECT_EQ(inspect::cache(r).resident_count(), 0u);  // prefetching never touches the device cache
  const HostBrickCache& host = inspect::loader(r).host_cache();
  EXPECT_EQ(host.policy_name(), "octreemizer");
  EXPECT_LE(host.bytes(), o.host_cache_bytes);
  EXPECT_GT(host.size(), 0u);

  // At rest: two equal poses predict nothing.
  const auto before = inspect::loader(r).stats().prefetched;
  for (int f = 0; f < 3; ++f) {
    const FrameReport rep = r.render_frame(s);
    if (f > 0) {
      EXPECT_EQ(rep.stats.prefetch_queued, 0u);
    }
    r.wait_for_loads();
  }
  EXPECT_LE(inspect::loader(r).stats().prefetched - before, 16u);  // only the first frame's queue
}

}  // namespace
}  // namespace resoct
