// Request set: deduplication, exact drop counting, drain order, concurrent inserts from several
// threads, and the greedy/global request strategies.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <thread>

#include "resoct/kernel/request_key.glsl.h"
#include "resoct/engine/request_set.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
namespace k = resoct::kernel;

TEST(RequestSet, DeduplicatesAndCountsHits) {
  RequestSet rs(100);  // rounds up to 128
  EXPECT_EQ(rs.capacity(), 128u);
  std::map<std::uint32_t, std::uint32_t> ref;
  std::mt19937 gen(3);
  for (int i = 0; i < 2000; ++i) {
    const std::uint32_t key = std::uint32_t(gen() % 50) * 977u;
    const std::uint32_t hits = 1 + std::uint32_t(gen() % 3);
    EXPECT_TRUE(rs.insert(key, hits));
    ref[key] += hits;
  }
  EXPECT_EQ(rs.size(), ref.size());
  EXPECT_EQ(rs.dropped(), 0u);
  const RequestBatch b = rs.drain();
  ASSERT_EQ(b.requests.size(), ref.size());
  for (const Request& r : b.requests) EXPECT_EQ(r.hits, ref.at(r.key)) << r.key;
  EXPECT_EQ(rs.size(), 0u);
}

TEST(RequestSet, OverflowIsCountedExactly) {
  RequestSet rs(8, 8);  // probing covers the whole table: drops happen only when full
  for (std::uint32_t key = 0; key < 20; ++key) EXPECT_EQ(rs.insert(key * 3u), key < 8);
  EXPECT_EQ(rs.size(), 8u);
  EXPECT_EQ(rs.dropped(), 12u);
  EXPECT_TRUE(rs.insert(0));                            // stored keys still count hits when full
  EXPECT_FALSE(rs.insert(k::RESOCT_REQUEST_KEY_NONE));  // reserved: refused and counted
  const RequestBatch b = rs.drain();
  EXPECT_EQ(b.dropped, 13u);
  ASSERT_EQ(b.requests.size(), 8u);
  std::set<std::uint32_t> keys;
  for (const Request& r : b.requests) keys.insert(r.key);
  EXPECT_EQ(keys, (std::set<std::uint32_t>{0, 3, 6, 9, 12, 15, 18, 21}));
  EXPECT_EQ(rs.dropped(), 0u);  // drain starts a new frame
}

TEST(RequestSet, ProbeBoundDropsCollidingKeys) {
  const std::uint32_t log2 = 10;
  // Keys that share home bucket h: with max_probes = p only p of them fit.
  std::vector<std::uint32_t> same;
  std::uint32_t home = 0;
  for (std::uint32_t key = 0; same.size() < 4; ++key) {
    const std::uint32_t h = k::resoct_request_key_hash(key, log2);
    if (same.empty()) home = h;
    if (h == home) same.push_back(key);
  }
  for (std::uint32_t probes : {1u, 2u, 3u}) {
    RequestSet rs(1u << log2, probes);
    for (std::size_t i = 0; i < same.size(); ++i) EXPECT_EQ(rs.insert(same[i]), i < probes);
    EXPECT_EQ(rs.size(), probes);
    EXPECT_EQ(rs.dropped(), same.size() - probes);
  }
}

TEST(RequestSet, DrainOrdersCoarserLevelsThenCoverageThenKey) {
  RequestSet rs(256);
  std::vector<Request> ref;
  std::mt19937 gen(11);
  for (std::uint32_t key = 1; key <= 60; ++key) {
    const std::uint32_t hits = 1 + std::uint32_t(gen() % 4);  // many ties
    for (std::uint32_t h = 0; h < hits; ++h) rs.insert(key * 101u);
    ref.push_back({key * 101u, hits, key % 5});
  }
  const RequestBatch b = rs.drain([](std::uint32_t key) { return (key / 101u) % 5; });
  std::sort(ref.begin(), ref.end(), [](const Request& x, const Request& y) {
    return x.level != y.level ? x.level > y.level
           : x.hits != y.hits ? x.hits > y.hits
                              : x.key < y.key;
  });
  EXPECT_EQ(b.requests, ref);
  // The set is empty and reusable after a drain.
  EXPECT_EQ(rs.size(), 0u);
  EXPECT_TRUE(rs.insert(5));
  EXPECT_EQ(rs.drain().requests, (std::vector<Request>{{5, 1, 0}}));
  rs.insert(6);
  rs.clear();
  EXPECT_TRUE(rs.drain().requests.empty());
}

TEST(RequestSet, ConcurrentInsertsKeepEveryHitOrCountTheDrop) {
  constexpr int kThreads = 4;
  constexpr int kInserts = 100000;
  for (std::uint32_t capacity : {8192u, 2048u}) {  // roomy, then overfull (5000 distinct keys)
    RequestSet rs(capacity, 16);
    std::vector<std::map<std::uint32_t, std::uint32_t>> counts(kThreads);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&rs, &counts, t] {
        std::mt19937 gen(std::uint32_t(1000 + t));
        for (int i = 0; i < kInserts; ++i) {
          const std::uint32_t key = std::uint32_t(gen() % 5000) * 7919u + 1u;
          rs.insert(key);
          ++counts[std::size_t(t)][key];
        }
      });
    }
    for (std::thread& th : threads) th.join();
    std::map<std::uint32_t, std::uint64_t> total;
    for (const auto& c : counts)
      for (const auto& [key, n] : c) total[key] += n;
    const std::uint64_t dropped = rs.dropped();
    const RequestBatch b = rs.drain();
    std::uint64_t hit_sum = 0, dropped_ref = 0;
    std::set<std::uint32_t> stored;
    for (const Request& r : b.requests) {
      EXPECT_TRUE(stored.insert(r.key).second) << "key stored twice: " << r.key;
      ASSERT_TRUE(total.count(r.key)) << "key never inserted: " << r.key;
      // A key is either stored (then every insert found it) or dropped every time.
      EXPECT_EQ(r.hits, total[r.key]);
      hit_sum += r.hits;
    }
    for (const auto& [key, n] : total)
      if (!stored.count(key)) dropped_ref += n;
    EXPECT_EQ(hit_sum + dropped, std::uint64_t(kThreads) * kInserts);
    EXPECT_EQ(dropped, dropped_ref);
    EXPECT_EQ(b.dropped, dropped);
    if (capacity == 8192u) {
      EXPECT_GT(stored.size(), 4900u);
    } else {
      EXPECT_GT(dropped, 0u);
    }
  }
}

TEST(RequestSet, ConcurrentDistinctOverflowStoredPlusDroppedIsInserted) {
  constexpr std::uint32_t kThreads = 4, kPerThread = 10000;
  RequestSet rs(16384, 32);
  std::vector<std::thread> threads;
  for (std::uint32_t t = 0; t < kThreads; ++t) {
    threads.emplace_back([&rs, t] {
      for (std::uint32_t i = 0; i < kPerThread; ++i) rs.insert(t * kPerThread + i);
    });
  }
  for (std::thread& th : threads) th.join();
  EXPECT_EQ(std::uint64_t(rs.size()) + rs.dropped(), kThreads * kPerThread);
  EXPECT_LE(rs.size(), rs.capacity());
  const RequestBatch b = rs.drain();
  std::set<std::uint32_t> keys;
  for (const Request& r : b.requests) {
    EXPECT_LT(r.key, kThreads * kPerThread);
    EXPECT_EQ(r.hits, 1u);
    keys.insert(r.key);
  }
  EXPECT_EQ(keys.size(), b.requests.size());
  EXPECT_EQ(keys.size() + b.dropped, kThreads * kPerThread);
}

TEST(RequestSet, RejectsBadParameters) {
  EXPECT_RESOCT_ERROR(RequestSet(0), ErrorCode::invalid_argument, "capacity");
  EXPECT_RESOCT_ERROR(RequestSet((1u << 28) + 1), ErrorCode::invalid_argument, "capacity");
  EXPECT_RESOCT_ERROR(RequestSet(16, 0), ErrorCode::invalid_argument, "max_probes");
}

namespace {
// Brute force: the coarser brick whose level-0 footprint contains the finer brick's footprint.
glm::uvec3 ancestor_by_search(const BrickHierarchy& h, std::uint32_t l, glm::uvec3 b,
                              std::uint32_t to) {
  const Box3 fine = h.level0_box(l, b);
  const LevelInfo& li = h.level(to);
  std::vector<glm::uvec3> found;
  for (std::uint32_t z = 0; z < li.bricks.z; ++z)
    for (std::uint32_t y = 0; y < li.bricks.y; ++y)
      for (std::uint32_t x = 0; x < li.bricks.x; ++x) {
        const Box3 c = h.level0_box(to, {x, y, z});
        if (intersect(c, fine) == fine) found.push_back({x, y, z});
      }
  EXPECT_EQ(found.size(), 1u);
  return found.empty() ? glm::uvec3(~0u) : found.front();
}
}  // namespace

TEST(RequestStrategy, GreedyRequestsAncestorsGlobalOnlyTheTarget) {
  VolumeDesc v;
  v.extent = {100, 61, 9};  // anisotropic: z stays whole for a while
  const BrickHierarchy h(v, BrickLayout{glm::uvec3(6, 5, 4), 1});
  ASSERT_GT(h.level_count(), 3u);
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const LevelInfo& li = h.level(l);
    for (std::uint32_t z = 0; z < li.bricks.z; ++z)
      for (std::uint32_t y = 0; y < li.bricks.y; ++y)
        for (std::uint32_t x = 0; x < li.bricks.x; ++x) {
          const PageAddress t{1, l, {x, y, z}};
          EXPECT_EQ(bricks_to_request(h, t, RequestStrategy::global), std::vector<PageAddress>{t});
          const std::vector<PageAddress> g = bricks_to_request(h, t, RequestStrategy::greedy);
          ASSERT_EQ(g.size(), h.level_count() - l);
          EXPECT_EQ(g[0], t);
          for (std::uint32_t i = 1; i < g.size(); ++i) {
            EXPECT_EQ(g[i].slot, 1u);
            EXPECT_EQ(g[i].level, l + i);
            EXPECT_EQ(g[i].brick, ancestor_by_search(h, l, t.brick, l + i));
          }
        }
  }
  // Greedy stops below the first level that is available.
  const PageAddress t{0, 0, {15, 12, 2}};
  const std::vector<PageAddress> g = bricks_to_request(
      h, t, RequestStrategy::greedy, [](const PageAddress& a) { return a.level == 3; });
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g.back().level, 2u);
  EXPECT_RESOCT_ERROR(coarser_brick(h, 2, {0, 0, 0}, 1), ErrorCode::invalid_argument, "level");
}
