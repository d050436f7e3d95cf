// Request-set inserts per second, from one thread and from two threads sharing one set. Keys
// repeat as in a frame where many rays miss the same bricks: 4096 distinct keys per key set.
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <vector>

#include "resoct/engine/request_set.hpp"

namespace {

resoct::RequestSet& shared_set() {
  static resoct::RequestSet set(1u << 14, 16);
  return set;
}

// 64 Ki inserts drawn from 4096 distinct keys; `offset` separates the key sets of threads.
std::vector<std::uint32_t> make_keys(std::uint32_t seed, std::uint32_t offset = 0) {
  std::mt19937 gen(seed);
  std::vector<std::uint32_t> keys(1u << 16);
  for (std::uint32_t& k : keys) k = (std::uint32_t(gen() % 4096u) + offset) * 2654435761u >> 1;
  return keys;
}

void BM_RequestSetInsert(benchmark::State& state) {
  resoct::RequestSet& set = shared_set();
  const std::vector<std::uint32_t> keys = make_keys(std::uint32_t(state.thread_index() + 1));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(set.insert(keys[i]));
    i = (i + 1) & (keys.size() - 1);
  }
  state.SetItemsProcessed(state.iterations());
  if (state.thread_index() == 0) state.counters["distinct"] = double(set.size());
}

// Each thread asks for its own bricks (as rays in different screen regions do): measures scaling
// without contention on the same keys' hit counters.
void BM_RequestSetInsertDisjoint(benchmark::State& state) {
  static resoct::RequestSet set(1u << 15, 16);
  const auto t = std::uint32_t(state.thread_index());
  const std::vector<std::uint32_t> keys = make_keys(t + 1u, 4096u * t);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(set.insert(keys[i]));
    i = (i + 1) & (keys.size() - 1);
  }
  state.SetItemsProcessed(state.iterations());
}

// Fresh keys each frame: clear() then fill, which is what a frame does; measures the claim path.
void BM_RequestSetFillAndClear(benchmark::State& state) {
  resoct::RequestSet set(1u << 14, 16);
  const std::vector<std::uint32_t> keys = make_keys(7);
  for (auto _ : state) {
    for (std::uint32_t k : keys) set.insert(k);
    benchmark::DoNotOptimize(set.size());
    set.clear();
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(keys.size()));
}

}  // namespace

// One thread: CPU time. Two threads: wall time, the rate the shared set sustains.
BENCHMARK(BM_RequestSetInsert)->Threads(1);
BENCHMARK(BM_RequestSetInsert)->Threads(1)->Threads(2)->UseRealTime();
BENCHMARK(BM_RequestSetInsertDisjoint)->Threads(1)->Threads(2)->UseRealTime();
BENCHMARK(BM_RequestSetFillAndClear);
BENCHMARK_MAIN();
