#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <thread>

#include "resoct/cache/host_brick_cache.hpp"

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
TEST(HostBrickCache, LruOrderSurvivesGrowthOfThePolicy) {
  // 600 entries outgrow the initial policy size (256 slots) twice; a reference LRU list decides
  // which keys must remain after random touches and insertions.
  constexpr std::uint32_t kKeep = 500;
  HostBrickCache c(kKeep * kCost);
  std::mt19937 rng(11);
  std::vector<std::uint32_t> order;  // reference: front = least recently used
  auto use = [&](std::uint32_t x) {
    order.erase(std::remove(order.begin(), order.end(), x), order.end());
    order.push_back(x);
    if (order.size() > kKeep) order.erase(order.begin());
  };
  for (std::uint32_t x = 0; x < 900; ++x) {
    c.put(brick(x, 100));
    use(x);
    if (x > 10 && rng() % 3 == 0) {
      const std::uint32_t y = order[rng() % order.size()];
      ASSERT_NE(c.get(key(y)), nullptr) << y;
      use(y);
    }
  }
  EXPECT_EQ(c.size(), kKeep);
  for (std::uint32_t x : order) EXPECT_TRUE(c.contains(key(x))) << x;
  EXPECT_EQ(c.bytes(), kKeep * kCost);
}

TEST(HostBrickCache, OctreemizerEvictsTheLargestDiscardPriority) {
  // Levels 0..3, distance = x; weights as in the paper. Brute force: the evicted entry is the
  // one with the largest p = ka * age + kl * depth + kd * distance among the others.
  const OctreemizerWeights w{1.0, 16.0, 1.0};
  const std::uint32_t levels = 4;
  auto policy = std::make_unique<OctreemizerPolicy>(levels, w,
                                                    [](BrickKey k) { return double(k.brick().x); });
  HostBrickCache c(6 * kCost, std::move(policy));
  EXPECT_EQ(c.policy_name(), "octreemizer");
  std::mt19937 rng(5);
  struct Ref {
    BrickKey key;
    std::uint64_t last_use;
  };
  std::vector<Ref> ref;
  for (std::uint64_t frame = 1; frame <= 40; ++frame) {
    c.set_frame(frame);
    auto b = std::make_shared<HostBrick>();
    b->key = BrickKey(rng() % levels, 0, glm::uvec3(std::uint32_t(frame) * 7 % 50, 0, 0));
    b->voxels.assign(100, std::byte{1});
    if (c.contains(b->key)) continue;
    if (ref.size() == 6) {
      std::size_t worst = 0;
      double worst_p = -1.0;
      for (std::size_t i = 0; i < ref.size(); ++i) {
        const double p = w.ka * double(frame - ref[i].last_use) +
                         w.kl * double(levels - 1 - ref[i].key.level()) +
                         w.kd * double(ref[i].key.brick().x);
        if (p > worst_p) worst_p = p, worst = i;
      }
      c.put(b);
      EXPECT_FALSE(c.contains(ref[worst].key)) << "frame " << frame;
      ref.erase(ref.begin() + std::ptrdiff_t(worst));
    } else {
      c.put(b);
    }
    ref.push_back({b->key, frame});
    // Touch one older entry now and then: it becomes young again.
    if (frame % 4 == 0 && ref.size() > 1) {
      ASSERT_NE(c.get(ref.front().key), nullptr);
      ref.front().last_use = frame;
    }
    for (const Ref& r : ref) EXPECT_TRUE(c.contains(r.key));
  }
}

}  // namespace resoct
