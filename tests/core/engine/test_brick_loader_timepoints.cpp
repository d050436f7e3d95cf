// The loader and host cache of a time series: bricks are keyed by (key, timepoint), a switch
// drops what was queued or ready, and a load of the old timepoint still in flight at the switch
// completes into the host cache but is never delivered (a gated source holds it in flight, so
// the test needs no sleeps).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "resoct/engine/brick_loader.hpp"
#include "resoct/base/error.hpp"
#include "resoct/sources/timepoint_sources.hpp"
#include "support/time_series_source.hpp"

namespace resoct::test {
namespace {

std::vector<std::byte> brick_of(const BrickSource& s, BrickKey key) {
  std::vector<std::byte> out(s.hierarchy().layout().padded_voxels() * voxel_size(s.volume().type));
  s.read_brick(key, out);
  return out;
}

// A level-0 brick inside the ball at timepoints 0 and 1 with different voxels.
const BrickKey kKey{0, 0, glm::uvec3(1, 1, 1)};

TEST(TimeSeriesSources, SingleTimepointSourcesHaveOneAndOpenNoOther) {
  const auto series = make_moving_ball_series(3);
  const std::shared_ptr<const BrickSource> t0 = series;
  EXPECT_EQ(source_at_timepoint(t0, 0), t0);
  const auto t2 = source_at_timepoint(t0, 2);
  EXPECT_EQ(t2->timepoint(), 2u);
  EXPECT_NE(brick_of(*t2, kKey), brick_of(*t0, kKey));
  try {
    source_at_timepoint(t0, 3);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("timepoint"), std::string::npos) << e.what();
  }
  TimepointSources sources(t0, 1);
  EXPECT_EQ(sources.count(), 3u);
  EXPECT_EQ(sources.at(1)->timepoint(), 1u);
  EXPECT_EQ(sources.at(2)->timepoint(), 2u);  // keep = 1: timepoint 1 is dropped, 2 opened
  EXPECT_EQ(sources.at(0), t0);
}

TEST(TimeSeriesSources, DefaultSourceHasOneTimepoint) {
  class Plain : public BrickSource {
   public:
    Plain() : h_(VolumeDesc{}, BrickLayout{}) {}
    const BrickHierarchy& hierarchy() const override { return h_; }
    void read_brick(BrickKey, std::span<std::byte>) const override {}
    RegionMeta region_meta(std::uint32_t, const Box3&) const override { return {}; }
    std::string name() const override { return "plain"; }

   private:
    BrickHierarchy h_;
  };
  const auto plain = std::make_shared<Plain>();
  EXPECT_EQ(plain->timepoints(), 1u);
  EXPECT_EQ(plain->timepoint(), 0u);
  EXPECT_EQ(source_at_timepoint(plain, 0), plain);
  EXPECT_THROW(source_at_timepoint(plain, 1), Error);
  EXPECT_THROW(plain->open_timepoint(1), Error);
}

TEST(TimeSeriesHostCache, KeepsTheSameKeyOfTwoTimepointsApart) {
  HostBrickCache cache(1 << 20);
  auto a = std::make_shared<HostBrick>();
  a->key = kKey;
  a->voxels.assign(8, std::byte{1});
  auto b = std::make_shared<HostBrick>(*a);
  b->timepoint = 3;
  b->voxels.assign(8, std::byte{2});
  cache.put(a);
  cache.put(b);
  EXPECT_EQ(cache.size(), 2u);
  EXPECT_EQ(cache.get(kKey, 0), a);
  EXPECT_EQ(cache.get(kKey, 3), b);
  EXPECT_FALSE(cache.contains(kKey, 1));
}

TEST(TimeSeriesLoader, SynchronousSwitchDropsQueuedAndReadyBricks) {
  const auto series = make_moving_ball_series(5);
  BrickLoader loader(series, 0, 1 << 20);
  const std::vector<LoadRequest> want{LoadRequest{kKey, 1, 0, 0},
                                      LoadRequest{BrickKey(0, 0, glm::uvec3(2, 1, 1)), 1, 0, 0}};
  loader.request(want);
  ASSERT_EQ(loader.run_queued(1), 1u);
  EXPECT_EQ(loader.ready(), 1u);
  EXPECT_EQ(loader.queued(), 1u);
  loader.set_timepoint(2);
  EXPECT_EQ(loader.timepoint(), 2u);
  EXPECT_TRUE(loader.idle());
  loader.request(want);
  ASSERT_EQ(loader.run_queued(2), 2u);
  const auto ready = loader.take_ready();
  ASSERT_EQ(ready.size(), 2u);
  const auto t2 = source_at_timepoint(series, 2);
  for (const LoadedBrick& b : ready) {
    EXPECT_EQ(b.brick->timepoint, 2u);
    if (!b.brick->meta.constant) {
      EXPECT_EQ(b.brick->voxels, brick_of(*t2, b.brick->key));
    }
  }
  EXPECT_THROW(loader.set_timepoint(5), Error);
  EXPECT_EQ(loader.timepoint(), 2u);
}

TEST(TimeSeriesLoader, AStaleLoadInFlightAtTheSwitchIsNeverDelivered) {
  auto gate = std::make_shared<ReadGate>(std::set<std::uint32_t>{0});
  const auto series = make_moving_ball_series(5, 0, gate);
  BrickLoader loader(series, 1, 1 << 20);
  loader.request(std::vector<LoadRequest>{LoadRequest{kKey, 1, 0, 0}});
  gate->wait_for_waiting(1);  // timepoint 0's read is in flight, held at the gate
  EXPECT_EQ(loader.in_flight(), 1u);

  loader.set_timepoint(1);
  EXPECT_EQ(loader.in_flight(), 0u);  // the stale load no longer counts for the frame loop
  loader.request(std::vector<LoadRequest>{LoadRequest{kKey, 1, 0, 0}});
  // The single worker is busy with the stale read: release it, then everything completes.
  gate->open();
  loader.wait_idle();
  const auto ready = loader.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready[0].brick->timepoint, 1u);
  EXPECT_EQ(ready[0].brick->voxels, brick_of(*source_at_timepoint(series, 1), kKey));
  const BrickLoaderStats st = loader.stats();
  EXPECT_EQ(st.stale_dropped, 1u);
  EXPECT_EQ(st.timepoint_switches, 1u);
  // The stale read still filled the host cache under its own timepoint.
  EXPECT_TRUE(loader.host_cache().contains(kKey, 0));
  EXPECT_TRUE(loader.host_cache().contains(kKey, 1));
}

TEST(TimeSeriesLoader, PrefetchOfTheNextTimepointServesItsRequestsFromTheHostCache) {
  const auto series = make_moving_ball_series(5);
  BrickLoader loader(series, 0, 1 << 20);
  const std::vector<TimedBrickKey> next{TimedBrickKey{kKey, 1}};
  loader.prefetch(std::span<const TimedBrickKey>(next));
  ASSERT_EQ(loader.run_prefetch(4), 1u);
  EXPECT_TRUE(loader.host_cache().contains(kKey, 1));
  EXPECT_FALSE(loader.host_cache().contains(kKey, 0));
  loader.set_timepoint(1);
  loader.request(std::vector<LoadRequest>{LoadRequest{kKey, 1, 0, 0}});
  ASSERT_EQ(loader.run_queued(1), 1u);
  const BrickLoaderStats st = loader.stats();
  EXPECT_EQ(st.prefetched, 1u);
  EXPECT_EQ(st.prefetch_hits, 1u);
  EXPECT_EQ(st.loads, 0u);
}

}  // namespace
}  // namespace resoct::test
