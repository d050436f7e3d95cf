#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>
#include <map>
#include <mutex>
#include <random>
#include <set>

#include "resoct/engine/brick_loader.hpp"
#include "resoct/base/error.hpp"
#include "support/expect_error.hpp"
#include "support/function_source.hpp"

namespace resoct {
namespace {

/// Wraps a FunctionSource: records every read in order and throws for chosen keys.
class RecordingSource : public BrickSource {
 public:
  explicit RecordingSource(std::set<BrickKey> failing = {})
      : inner_(
            [] {
              VolumeDesc v;
              v.extent = {32, 32, 16};
              v.type = VoxelType::u8;
              v.channels = 2;
              return v;
            }(),
            BrickLayout{glm::uvec3(8), 1},
            [](std::uint32_t c, const glm::u64vec3& p) {
              if (p.x < 12) return 0.0;  // empty and constant bricks exist
              return double((p.x * 7 + p.y * 3 + p.z * 5 + c * 11) % 200 + 1);
            },
            "recording-source"),
        failing_(std::move(failing)) {}
  const BrickHierarchy& hierarchy() const override { return inner_.hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    {
      std::lock_guard lock(mutex_);
      reads_.push_back(key);
    }
    if (failing_.count(key)) {
      std::lock_guard lock(mutex_);
      // A failure that passes: the first `fail_times_` reads of each failing key throw.
      if (fail_times_ < 0 || failed_reads_[key]++ < fail_times_) {
        throw Error(fail_code_, "injected failure");
      }
    }
    inner_.read_brick(key, out);
  }
  /// Failing keys throw Error(code) on their first `times` reads (-1: always).
  void fail_with(ErrorCode code, int times) {
    std::lock_guard lock(mutex_);
    fail_code_ = code;
    fail_times_ = times;
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_.region_meta(c, b);
  }
  std::string name() const override { return "recording-source"; }
  std::vector<BrickKey> reads() const {
    std::lock_guard lock(mutex_);
    return reads_;
  }

 private:
  test::FunctionSource inner_;
  std::set<BrickKey> failing_;
  ErrorCode fail_code_ = ErrorCode::io;
  int fail_times_ = -1;
  mutable std::map<BrickKey, int> failed_reads_;
  mutable std::mutex mutex_;
  mutable std::vector<BrickKey> reads_;
};

std::vector<LoadRequest> all_requests(const BrickHierarchy& h, std::uint32_t seed) {
  std::vector<LoadRequest> out;
  std::mt19937 rng(seed);
  for (std::uint32_t c = 0; c < h.volume().channels; ++c) {
    for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i) {
      out.push_back(LoadRequest{h.key_from_linear(c, i), std::uint32_t(rng() % 4)});
    }
  }
  std::shuffle(out.begin(), out.end(), rng);
  return out;
}

TEST(BrickLoader, LoadsCoarserLevelsFirstThenMoreHits) {
  auto src = std::make_shared<RecordingSource>();
  BrickLoader loader(src, 0, 1 << 20);
  const auto reqs = all_requests(src->hierarchy(), 7);
  loader.request(reqs);
  EXPECT_EQ(loader.queued(), reqs.size());
  EXPECT_EQ(loader.run_queued(reqs.size() + 5), reqs.size());
  // Brute-force expected order: level descending, hits descending, key ascending.
  auto expected = reqs;
  std::sort(expected.begin(), expected.end(), [](const LoadRequest& a, const LoadRequest& b) {
    if (a.key.level() != b.key.level()) return a.key.level() > b.key.level();
    if (a.hits != b.hits) return a.hits > b.hits;
    return a.key.bits() < b.key.bits();
  });
  const auto reads = src->reads();
  ASSERT_EQ(reads.size(), expected.size());
  for (std::size_t i = 0; i < reads.size(); ++i) EXPECT_EQ(reads[i], expected[i].key) << i;
  const auto ready = loader.take_ready();
  ASSERT_EQ(ready.size(), expected.size());
  for (std::size_t i = 0; i < ready.size(); ++i) EXPECT_EQ(ready[i].brick->key, expected[i].key);
}

TEST(BrickLoader, DeliversVoxelsAndMetadataOfTheSource) {
  auto src = std::make_shared<RecordingSource>();
  BrickLoader loader(src, 0, 1 << 20);
  loader.request(all_requests(src->hierarchy(), 3));
  loader.run_queued(1000);
  const std::size_t bytes = src->hierarchy().layout().padded_voxels();
  std::size_t constant = 0;
  for (const LoadedBrick& b : loader.take_ready()) {
    std::vector<std::byte> want(bytes);
    src->read_brick(b.brick->key, want);
    EXPECT_EQ(b.brick->meta, scan_brick(want, VoxelType::u8));
    if (b.brick->meta.constant) {
      ++constant;
      EXPECT_TRUE(b.brick->voxels.empty());
    } else {
      EXPECT_EQ(b.brick->voxels, want);
    }
  }
  EXPECT_GT(constant, 0u);  // x < 12 gives all-zero level-0 bricks
}

// With the residency octree's layout the loader scans each level-0 brick's leaves on its own
// threads (LoadedBrick::leaves): the records scan_leaves gives for the voxels it delivers, over the
// channel's range; level > 0 and constant bricks carry none, and without a layout nothing is
// scanned.
TEST(BrickLoader, ScansLevel0LeavesOnItsThreadsWhenGivenTheOctreeLayout) {
  auto src = std::make_shared<RecordingSource>();
  const BrickHierarchy& h = src->hierarchy();
  auto layout = std::make_shared<const OctreeLayout>(h.volume().extent, glm::uvec3(4));
  BrickLoader loader(src, 2, 1 << 20, nullptr, layout);
  loader.request(all_requests(h, 4));
  loader.wait_idle();
  std::size_t scanned = 0;
  for (const LoadedBrick& b : loader.take_ready()) {
    const HostBrick& hb = *b.brick;
    if (hb.key.level() != 0 || hb.meta.constant) {
      EXPECT_TRUE(b.leaves.empty());
      EXPECT_EQ(b.leaf_size, glm::uvec3(0));
      continue;
    }
    ++scanned;
    EXPECT_EQ(b.leaf_size, glm::uvec3(4));
    EXPECT_EQ(b.leaves, scan_leaves(*layout, h, h.volume().range(hb.key.channel()), hb.key.brick(),
                                    hb.voxels));
    EXPECT_EQ(b.leaves.size(), 8u);  // 8³ bricks, 4³ leaves
  }
  EXPECT_GT(scanned, 0u);
  // Requested again: served by the host cache, and scanned again.
  loader.request(all_requests(h, 4));
  loader.wait_idle();
  std::size_t rescanned = 0;
  for (const LoadedBrick& b : loader.take_ready()) {
    if (b.brick->key.level() == 0 && !b.brick->meta.constant) {
      EXPECT_EQ(b.leaf_size, glm::uvec3(4));
      EXPECT_EQ(b.leaves.size(), 8u);
      ++rescanned;
    }
  }
  EXPECT_EQ(rescanned, scanned);
  EXPECT_EQ(loader.stats().host_hits, loader.stats().loads);

  BrickLoader plain(src, 0, 1 << 20);
  plain.request(all_requests(h, 4));
  plain.run_queued(1000);
  for (const LoadedBrick& b : plain.take_ready()) {
    EXPECT_TRUE(b.leaves.empty());
    EXPECT_EQ(b.leaf_size, glm::uvec3(0));
  }
}

TEST(BrickLoader, DeduplicatesQueuedReadyAndCachedKeys) {
  auto src = std::make_shared<RecordingSource>();
  BrickLoader loader(src, 0, 1 << 20);
  const BrickKey a(0, 0, {2, 1, 0}), b(0, 1, {3, 2, 1});
  const std::vector<LoadRequest> twice{{a, 1}, {b, 1}, {a, 5}};
  loader.request(twice);
  EXPECT_EQ(loader.queued(), 2u);
  loader.run_queued(10);
  loader.request(twice);  // both ready, not taken: nothing is queued again
  EXPECT_EQ(loader.queued(), 0u);
  EXPECT_EQ(loader.take_ready().size(), 2u);
  EXPECT_EQ(src->reads().size(), 2u);
  loader.request(twice);  // taken: queued again, but served by the host cache
  loader.run_queued(10);
  EXPECT_EQ(src->reads().size(), 2u);
  EXPECT_EQ(loader.stats().host_hits, 2u);
  EXPECT_EQ(loader.take_ready().size(), 2u);
  EXPECT_TRUE(loader.idle());
}

TEST(BrickLoader, NewRequestListCancelsQueuedKeys) {
  auto src = std::make_shared<RecordingSource>();
  BrickLoader loader(src, 0, 1 << 20);
  const BrickKey a(2, 0, {0, 0, 0}), b(1, 0, {1, 0, 0}), c(0, 0, {3, 0, 0}), d(0, 0, {3, 1, 0});
  const std::vector<LoadRequest> first{{c, 1}, {b, 1}, {a, 1}};
  loader.request(first);
  ASSERT_EQ(loader.run_queued(1), 1u);  // a: the coarsest
  const std::vector<LoadRequest> second{{d, 9}, {c, 1}};
  loader.request(second);
  EXPECT_EQ(loader.stats().cancelled, 1u);  // b
  loader.run_queued(10);
  EXPECT_EQ(src->reads(), (std::vector<BrickKey>{a, d, c}));
}

TEST(BrickLoader, FailuresAreReportedOnceAndNeverRetried) {
  const BrickKey bad(0, 1, {2, 2, 1});
  auto src = std::make_shared<RecordingSource>(std::set<BrickKey>{bad});
  BrickLoader loader(src, 0, 1 << 20);
  const std::vector<LoadRequest> reqs{{bad, 1}, {BrickKey(0, 1, {3, 2, 1}), 1}};
  loader.request(reqs);
  loader.run_queued(10);
  const auto failures = loader.take_failures();
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0].key, bad);
  EXPECT_NE(failures[0].message.find("recording-source"), std::string::npos);
  EXPECT_NE(failures[0].message.find("injected failure"), std::string::npos);
  EXPECT_TRUE(loader.has_failed(bad));
  EXPECT_EQ(loader.take_ready().size(), 1u);
  loader.request(reqs);
  EXPECT_EQ(loader.queued(), 1u);  // only the good brick (served from the host cache)
  loader.run_queued(10);
  EXPECT_TRUE(loader.take_failures().empty());
  const auto reads = src->reads();
  EXPECT_EQ(std::count(reads.begin(), reads.end(), bad), 1);
}

TEST(BrickLoader, TransientFailuresAreRetriedAfterTheirDelayAndReportedOnce) {
  const BrickKey bad(0, 1, {2, 2, 1});
  auto src = std::make_shared<RecordingSource>(std::set<BrickKey>{bad});
  src->fail_with(ErrorCode::io, 2);  // fails twice, then reads
  BrickLoader loader(src, 0, 1 << 20);
  loader.set_transient_retry(std::chrono::milliseconds(200));
  const std::vector<LoadRequest> reqs{{bad, 1}};
  const auto read_count = [&] {
    const auto r = src->reads();
    return std::count(r.begin(), r.end(), bad);
  };

  loader.request(reqs);
  loader.run_queued(10);
  ASSERT_EQ(loader.take_failures().size(), 1u);
  EXPECT_TRUE(loader.has_failed(bad));
  EXPECT_EQ(loader.retries_pending(), 1u);
  loader.request(reqs);  // too early: still failed, not read again
  EXPECT_EQ(loader.run_queued(10), 0u);
  EXPECT_EQ(read_count(), 1);

  // Sleeps only ever last longer: checks that a retry is not yet due have 150 ms or more of
  // margin, checks that it is due have none to lose.
  std::this_thread::sleep_for(std::chrono::milliseconds(210));
  EXPECT_FALSE(loader.has_failed(bad));  // due
  loader.request(reqs);
  loader.run_queued(10);  // the second failure: reported before, so not again
  EXPECT_TRUE(loader.take_failures().empty());
  EXPECT_EQ(read_count(), 2);
  EXPECT_TRUE(loader.has_failed(bad));  // now 400 ms: twice the delay
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  EXPECT_TRUE(loader.has_failed(bad));
  std::this_thread::sleep_for(std::chrono::milliseconds(160));
  loader.request(reqs);
  loader.run_queued(10);
  EXPECT_EQ(read_count(), 3);
  ASSERT_EQ(loader.take_ready().size(), 1u);  // the third read succeeded
  EXPECT_FALSE(loader.has_failed(bad));
  EXPECT_EQ(loader.retries_pending(), 0u);
  EXPECT_EQ(loader.stats().retries, 2u);
  EXPECT_EQ(loader.stats().failures, 1u);
}

TEST(BrickLoader, CorruptDataIsNeverRetried) {
  const BrickKey bad(0, 1, {2, 2, 1});
  auto src = std::make_shared<RecordingSource>(std::set<BrickKey>{bad});
  src->fail_with(ErrorCode::checksum_mismatch, 1);  // would read on the second try
  BrickLoader loader(src, 0, 1 << 20);
  loader.set_transient_retry(std::chrono::milliseconds(1));
  const std::vector<LoadRequest> reqs{{bad, 1}};
  loader.request(reqs);
  loader.run_queued(10);
  ASSERT_EQ(loader.take_failures().size(), 1u);
  EXPECT_EQ(loader.retries_pending(), 0u);
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(loader.has_failed(bad));
  loader.request(reqs);
  EXPECT_EQ(loader.run_queued(10), 0u);
  EXPECT_EQ(loader.stats().retries, 0u);
}

TEST(BrickLoader, TransientRetryDelayIsChecked) {
  BrickLoader loader(std::make_shared<RecordingSource>(), 0, 1 << 20);
  EXPECT_RESOCT_ERROR(loader.set_transient_retry(std::chrono::hours(2)),
                      ErrorCode::invalid_argument, "retry_after_ms");
  EXPECT_RESOCT_ERROR(loader.set_transient_retry(std::chrono::milliseconds(-1)),
                      ErrorCode::invalid_argument, "retry_after_ms");
}

TEST(BrickLoader, ThreadsReadEveryKeyExactlyOnce) {
  const auto h = RecordingSource().hierarchy();
  std::set<BrickKey> failing;
  for (std::uint64_t i = 0; i < h.bricks_per_channel(); i += 7) {
    failing.insert(h.key_from_linear(1, i));
  }
  auto src = std::make_shared<RecordingSource>(failing);
  BrickLoader loader(src, 4, 1 << 20);
  const auto reqs = all_requests(h, 11);
  std::map<BrickKey, int> delivered;
  std::size_t failures = 0;
  // Re-requesting while the workers run must not duplicate keys in flight or ready. A key taken
  // before a later round may be delivered again (from the host cache, never read again), so
  // only totals are deterministic.
  for (int round = 0; round < 3; ++round) {
    loader.request(reqs);
    for (const LoadedBrick& b : loader.take_ready()) ++delivered[b.brick->key];
    failures += loader.take_failures().size();
  }
  loader.wait_idle();
  for (const LoadedBrick& b : loader.take_ready()) ++delivered[b.brick->key];
  failures += loader.take_failures().size();
  EXPECT_EQ(failures, failing.size());
  std::map<BrickKey, int> reads;
  for (BrickKey k : src->reads()) ++reads[k];
  for (const LoadRequest& r : reqs) {
    EXPECT_EQ(reads[r.key], 1) << "each key read once";
    EXPECT_EQ(delivered.count(r.key), failing.count(r.key) ? 0u : 1u);
  }
  const BrickLoaderStats st = loader.stats();
  EXPECT_EQ(st.loads, reqs.size() - failing.size());
  std::uint64_t deliveries = 0;
  for (const auto& [k, n] : delivered) deliveries += std::uint64_t(n);
  EXPECT_EQ(deliveries, st.loads + st.host_hits);
  EXPECT_TRUE(loader.idle());
}

TEST(BrickLoader, LowerRankThenOlderRequestsOfALevelGoFirst) {
  auto src = std::make_shared<RecordingSource>();
  BrickLoader loader(src, 0, 1 << 20);
  const BrickKey young(0, 0, {0, 0, 0}), old(0, 0, {3, 3, 1}), coarse(1, 0, {1, 1, 0});
  // Age beats hits and key within a level; a coarser level beats age.
  const BrickKey important(0, 1, {2, 2, 1});
  // Rank beats age within a level.
  const std::vector<LoadRequest> reqs{
      {young, 50, 9, 1}, {old, 1, 2, 1}, {coarse, 1, 9, 1}, {important, 1, 20, 0}};
  loader.request(reqs);
  loader.run_queued(10);
  EXPECT_EQ(src->reads(), (std::vector<BrickKey>{coarse, important, old, young}));
}

TEST(BrickLoader, RejectsBadParameters) {
  EXPECT_RESOCT_ERROR(BrickLoader(nullptr, 0, 0), ErrorCode::invalid_argument, "source");
  EXPECT_RESOCT_ERROR(BrickLoader(std::make_shared<RecordingSource>(), 5000, 0),
                      ErrorCode::invalid_argument, "threads");
}

}  // namespace
}  // namespace resoct
