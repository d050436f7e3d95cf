#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "resoct/host_brick_cache.hpp"

namespace resoct {
namespace {

std::shared_ptr<const HostBrick> brick(std::uint32_t x, std::size_t bytes) {
  auto b = std::make_shared<HostBrick>();
  b->key = BrickKey(0, 0, glm::uvec3(x, 0, 0));
  b->voxels.assign(bytes, std::byte{static_cast<unsigned char>(x)});
  return b;
}

BrickKey key(std::uint32_t x) {
  return BrickKey(0, 0, glm::uvec3(x, 0, 0));
}

constexpr std::uint64_t kCost = 100 + HostBrickCache::kEntryOverhead;

TEST(HostBrickCache, EvictsLeastRecentlyUsedByBytes) {
  HostBrickCache c(3 * kCost);
  c.put(brick(1, 100));
  c.put(brick(2, 100));
  c.put(brick(3, 100));
  ASSERT_NE(c.get(key(1)), nullptr);  // 1 becomes most recent: 2 is now the oldest
  c.put(brick(4, 100));
  EXPECT_TRUE(c.contains(key(1)));
  EXPECT_FALSE(c.contains(key(2)));
  EXPECT_TRUE(c.contains(key(3)));
  EXPECT_TRUE(c.contains(key(4)));
  EXPECT_EQ(c.bytes(), 3 * kCost);
  EXPECT_EQ(c.stats().evictions, 1u);
  // A larger brick evicts as many old ones as its bytes need: 3 then 1 (the two oldest).
  c.put(brick(5, 250));
  EXPECT_FALSE(c.contains(key(3)));
  EXPECT_FALSE(c.contains(key(1)));
  EXPECT_TRUE(c.contains(key(4)));
  EXPECT_EQ(c.bytes(), kCost + 250 + HostBrickCache::kEntryOverhead);
}

TEST(HostBrickCache, HandedOutBrickSurvivesEviction) {
  HostBrickCache c(kCost);
  c.put(brick(1, 100));
  auto held = c.get(key(1));
  c.put(brick(2, 100));
  EXPECT_FALSE(c.contains(key(1)));
  ASSERT_NE(held, nullptr);
  EXPECT_EQ(held->voxels.size(), 100u);
  EXPECT_EQ(held->voxels[0], std::byte{1});
}

TEST(HostBrickCache, OversizedBrickAndZeroCapacityKeepNothing) {
  HostBrickCache c(kCost);
  c.put(brick(1, 100));
  c.put(brick(2, 101));  // costs more than the capacity: refused, the old entry stays
  EXPECT_TRUE(c.contains(key(1)));
  EXPECT_FALSE(c.contains(key(2)));
  HostBrickCache off(0);
  off.put(brick(1, 0));
  EXPECT_EQ(off.size(), 0u);
  EXPECT_EQ(off.get(key(1)), nullptr);
  EXPECT_EQ(off.stats().misses, 1u);
}

TEST(HostBrickCache, ReplacingAKeyReaccountsItsBytes) {
  HostBrickCache c(10 * kCost);
  c.put(brick(1, 100));
  c.put(brick(1, 40));
  EXPECT_EQ(c.size(), 1u);
  EXPECT_EQ(c.bytes(), 40 + HostBrickCache::kEntryOverhead);
  EXPECT_EQ(c.get(key(1))->voxels.size(), 40u);
}

TEST(HostBrickCache, ConcurrentUseKeepsTheByteBound) {
  HostBrickCache c(20 * kCost);
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < 4; ++t) {
    threads.emplace_back([&c, t] {
      std::mt19937 rng(1234 + t);
      for (int i = 0; i < 2000; ++i) {
        const std::uint32_t x = rng() % 64;
        if (rng() % 2) {
          c.put(brick(x, 100));
        } else if (auto b = c.get(key(x))) {
          // Content must match the key: no torn or mixed-up entries.
          ASSERT_EQ(b->voxels[0], std::byte{static_cast<unsigned char>(x)});
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_LE(c.bytes(), 20 * kCost);
  EXPECT_EQ(c.bytes(), c.size() * kCost);
  std::size_t present = 0;
  for (std::uint32_t x = 0; x < 64; ++x) present += c.contains(key(x)) ? 1u : 0u;
  EXPECT_EQ(present, c.size());
}

}  // namespace
}  // namespace resoct
