// Brick-cache bookkeeping throughput with 10^5 resident bricks: touch (mark used this frame) and
// evict (insert a new brick into a full cache, which evicts one). Reported as ns per operation.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <numeric>
#include <random>

#include "resoct/engine/brick_cache.hpp"

namespace {

constexpr std::uint32_t kResident = 100000;
const resoct::BrickLayout kLayout{glm::uvec3(32), 1};

resoct::BrickKey key(std::uint64_t i) {
  return resoct::BrickKey(std::uint32_t(i % 7), std::uint32_t((i / 7) % 4),
                          {std::uint32_t(i % 100003), std::uint32_t(i / 100003) & 0x1FFFF, 0});
}

std::unique_ptr<resoct::EvictionPolicy> make_policy(std::int64_t kind) {
  if (kind == 0) return std::make_unique<resoct::LruPolicy>();
  return std::make_unique<resoct::OctreemizerPolicy>(
      7, resoct::OctreemizerWeights{}, [](resoct::BrickKey k) { return double(k.brick().x % 97); });
}

std::unique_ptr<resoct::BrickCache> full_cache(std::int64_t kind) {
  auto c = std::make_unique<resoct::BrickCache>(
      kLayout, resoct::VoxelType::u8, kLayout.padded_voxels() * kResident, 2, make_policy(kind));
  c->begin_frame(1);
  for (std::uint64_t i = 0; i < kResident; ++i) c->insert(key(i));
  return c;
}

// One touch per resident brick per frame, in random order: every touch moves a brick to the
// most-recent end (a repeated touch within a frame would be a no-op and flatter the number).
void BM_CacheTouch(benchmark::State& state) {
  auto cache = full_cache(state.range(0));
  std::vector<std::uint32_t> order(kResident);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), std::mt19937(42));
  std::uint64_t frame = 10;
  std::size_t i = 0;
  cache->begin_frame(frame);
  for (auto _ : state) {
    cache->touch(order[i]);
    if (++i == order.size()) {
      i = 0;
      cache->begin_frame(++frame);
    }
  }
  benchmark::ClobberMemory();
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(state.range(0) == 0 ? "lru" : "octreemizer");
}

// Insert of a new brick into the full cache: policy victim + index update + bookkeeping. Frames
// advance every 10^4 inserts so that victims (older than ttl) always exist.
void BM_CacheEvict(benchmark::State& state) {
  auto cache = full_cache(state.range(0));
  std::uint64_t frame = 10, next = kResident, since = 0;
  cache->begin_frame(frame);
  for (auto _ : state) {
    auto ins = cache->insert(key(next++));
    benchmark::DoNotOptimize(ins);
    if (++since == 10000) {
      since = 0;
      frame += 3;
      cache->begin_frame(frame);
    }
  }
  if (cache->stats().allocation_failures != 0) state.SkipWithError("allocation failed");
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(state.range(0) == 0 ? "lru" : "octreemizer");
}

}  // namespace

BENCHMARK(BM_CacheTouch)->Arg(0)->Arg(1);
BENCHMARK(BM_CacheEvict)->Arg(0)->Arg(1);
BENCHMARK_MAIN();
