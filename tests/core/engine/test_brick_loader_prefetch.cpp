// BrickLoader prefetching: prefetched bricks go to the host cache only, run after every real
// request, are skipped when already known, are delivered (not read twice) when requested while
// loading, and fail once like requests.
#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>
#include <set>

#include "resoct/engine/brick_loader.hpp"
#include "resoct/base/error.hpp"
#include "support/function_source.hpp"

namespace resoct {
namespace {

VolumeDesc test_volume() {
  VolumeDesc v;
  v.extent = {32, 32, 16};
  v.type = VoxelType::u8;
  v.channels = 1;
  return v;
}

/// Records reads; can hold a chosen key's read until released, and fail chosen keys.
class GateSource : public BrickSource {
 public:
  GateSource()
      : inner_(
            test_volume(), BrickLayout{glm::uvec3(8), 1},
            [](std::uint32_t, const glm::u64vec3& p) {
              return double((p.x + 2 * p.y + p.z) % 250 + 1);
            },
            "gate-source") {}
  const BrickHierarchy& hierarchy() const override { return inner_.hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    std::unique_lock lock(mutex_);
    reads_.push_back(key);
    if (gate_ && *gate_ == key) {
      entered_ = true;
      cv_.notify_all();
      cv_.wait(lock, [this] { return open_; });
    }
    if (failing_.count(key)) throw Error(ErrorCode::io, "injected failure");
    lock.unlock();
    inner_.read_brick(key, out);
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_.region_meta(c, b);
  }
  std::string name() const override { return "gate-source"; }

  std::vector<BrickKey> reads() const {
    std::lock_guard lock(mutex_);
    return reads_;
  }
  void hold(BrickKey key) {
    std::lock_guard lock(mutex_);
    gate_ = key;
    open_ = false;
  }
  void wait_entered() {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [this] { return entered_; });
  }
  void release() {
    std::lock_guard lock(mutex_);
    open_ = true;
    cv_.notify_all();
  }
  std::set<BrickKey> failing_;

 private:
  test::FunctionSource inner_;
  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  mutable std::vector<BrickKey> reads_;
  std::optional<BrickKey> gate_;
  mutable bool entered_ = false;
  bool open_ = true;
};

BrickKey k(std::uint32_t x, std::uint32_t y = 0) {
  return BrickKey(0, 0, glm::uvec3(x, y, 0));
}

TEST(BrickLoaderPrefetch, LoadsIntoTheHostCacheOnlyAndAfterRequests) {
  auto src = std::make_shared<GateSource>();
  BrickLoader loader(src, 0, 1 << 20);
  const std::vector<BrickKey> pre = {k(0), k(1), k(2)};
  loader.prefetch(pre);
  const LoadRequest r{k(3), 1, 0, 0};
  loader.request(std::span(&r, 1));
  EXPECT_EQ(loader.prefetch_queued(), 3u);
  EXPECT_EQ(loader.run_queued(10), 1u);
  EXPECT_EQ(loader.run_prefetch(10), 3u);
  // Order: the request was read first (run_queued), then the prefetches in their given order.
  EXPECT_EQ(src->reads(), (std::vector<BrickKey>{k(3), k(0), k(1), k(2)}));
  // Only the request is delivered; the prefetches wait in the host cache.
  const auto ready = loader.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready[0].brick->key, k(3));
  for (const BrickKey key : pre) EXPECT_TRUE(loader.host_cache().contains(key));
  EXPECT_TRUE(loader.idle());
  EXPECT_EQ(loader.stats().prefetched, 3u);

  // A later request of a prefetched brick is served by the host cache, not the source.
  const LoadRequest again{k(1), 1, 0, 0};
  loader.request(std::span(&again, 1));
  EXPECT_EQ(loader.run_queued(10), 1u);
  EXPECT_EQ(src->reads().size(), 4u);
  EXPECT_EQ(loader.stats().prefetch_hits, 1u);
  EXPECT_EQ(loader.take_ready().size(), 1u);

  // Known keys are not prefetched again; a new list replaces the old one.
  loader.prefetch(pre);
  EXPECT_EQ(loader.prefetch_queued(), 0u);
  const std::vector<BrickKey> a = {k(0, 1), k(1, 1)}, b = {k(2, 1)};
  loader.prefetch(a);
  loader.prefetch(b);
  EXPECT_EQ(loader.run_prefetch(10), 1u);
  EXPECT_EQ(src->reads().back(), k(2, 1));
}

TEST(BrickLoaderPrefetch, ARequestDuringThePrefetchIsDeliveredWithoutASecondRead) {
  auto src = std::make_shared<GateSource>();
  src->hold(k(2));
  BrickLoader loader(src, 1, 1 << 20);
  const std::vector<BrickKey> pre = {k(2)};
  loader.prefetch(pre);
  src->wait_entered();  // the worker is reading k(2) as a prefetch
  const LoadRequest r{k(2), 5, 0, 0};
  loader.request(std::span(&r, 1));
  EXPECT_FALSE(loader.idle());  // the request is outstanding until the prefetch completes
  src->release();
  loader.wait_idle();
  const auto ready = loader.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready[0].brick->key, k(2));
  EXPECT_EQ(ready[0].hits, 5u);
  EXPECT_EQ(src->reads().size(), 1u);
  EXPECT_EQ(loader.stats().prefetch_hits, 1u);
  EXPECT_TRUE(loader.idle());
}

TEST(BrickLoaderPrefetch, AFailedPrefetchIsReportedOnceAndNeverRequested) {
  auto src = std::make_shared<GateSource>();
  src->failing_ = {k(1)};
  BrickLoader loader(src, 0, 1 << 20);
  const std::vector<BrickKey> pre = {k(1)};
  loader.prefetch(pre);
  EXPECT_EQ(loader.run_prefetch(5), 1u);
  const auto f = loader.take_failures();
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NE(f[0].message.find("gate-source: brick level 0 channel 0 (1, 0, 0): injected failure"),
            std::string::npos)
      << f[0].message;
  EXPECT_TRUE(loader.has_failed(k(1)));
  const LoadRequest r{k(1), 1, 0, 0};
  loader.request(std::span(&r, 1));
  EXPECT_EQ(loader.run_queued(5), 0u);
  EXPECT_TRUE(loader.take_failures().empty());
}

}  // namespace
}  // namespace resoct
