// Page-table address translation (level, slot, normalized position -> entry, cache slot and
// voxel inside the padded brick) per second.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "resoct/engine/page_table.hpp"

namespace {

void BM_PageTableTranslate(benchmark::State& state) {
  resoct::VolumeDesc v;
  v.extent = {1024, 1024, 795};
  const resoct::BrickHierarchy h(v, resoct::BrickLayout{glm::uvec3(32), 1});
  resoct::PageTable pt(h, 4, std::uint32_t(resoct::PageTable::block_count(h, 4)));
  // Every block allocated: translate() reads a real pool block, as it does for resident data.
  for (std::uint32_t d = 0; d < pt.directory().size(); ++d) pt.allocate_block(d);
  std::mt19937 gen(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct Query {
    glm::dvec3 p;
    std::uint32_t level, slot;
  };
  std::vector<Query> q(4096);
  for (Query& x : q) {
    x.p = {u(gen), u(gen), u(gen)};
    x.level = std::uint32_t(gen() % h.level_count());
    x.slot = std::uint32_t(gen() % 4);
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const Query& x = q[i];
    benchmark::DoNotOptimize(pt.translate(x.level, x.slot, x.p));
    i = (i + 1) & (q.size() - 1);
  }
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

BENCHMARK(BM_PageTableTranslate);
BENCHMARK_MAIN();
