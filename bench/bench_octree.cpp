// Residency octree update cost per brick add and evict, against tree depth (leaf size), visible
// slots and brick level, on a 2048³ hierarchy with 32³ bricks (256³ with RESOCT_BENCH_SMOKE=1,
// the ctest smoke run, where building the 2048³ trees alone took ~50 s).
//
//   BM_OctreeAddEvict/<leaf>/<slots>/<level>  one brick_added + one brick_evicted per item
//   BM_OctreeAdd/..., BM_OctreeEvict/...      the two halves separately, in batches of distinct
//                                             bricks (the other half paused, and its share of
//                                             the counters taken out)
//   BM_OctreeMetadataFromBrick/<leaf>/<smooth> exact leaf metadata from one level-0 brick
//   BM_OctreeLeafMetadata/<leaf>               storing a level-0 brick's leaf records scanned
//                                             elsewhere (the frame thread's share since the
//                                             loader threads scan, scan_leaves)
// ns_per_brick is CPU time per item (per add+evict pair, or per add / per evict); Google Benchmark
// prints inverted rates with an "s" suffix, so "907.6s" there means 907.6 ns.
//
// A quarter of the level-0 bricks of every slot stay resident in the background, so upward
// propagation meets already-set ancestors as it would in a running renderer. take_deltas() runs
// every 1024 items and is included in the time. Configurations whose node storage would exceed
// kMaxStorage are skipped with a message; bytes_per_node reports what they would need.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "resoct/engine/leaf_scan.hpp"
#include "resoct/engine/residency_octree.hpp"

namespace {

using namespace resoct;

std::uint64_t extent() {
  const char* smoke = std::getenv("RESOCT_BENCH_SMOKE");
  const bool small = smoke != nullptr && *smoke != '\0' && std::strcmp(smoke, "0") != 0;
  return small ? 256 : 2048;
}
constexpr std::uint64_t kMaxStorage = std::uint64_t(1536) << 20;  // bytes of node words

struct Setup {
  BrickHierarchy hierarchy;
  std::vector<std::vector<std::uint8_t>> resident;  // [slot][linear brick index]

  explicit Setup(std::uint32_t slots) : hierarchy(make()), resident(slots) {
    for (auto& r : resident) r.assign(hierarchy.bricks_per_channel(), 0);
  }
  static BrickHierarchy make() {
    VolumeDesc v;
    v.extent = glm::u64vec3(extent());
    v.type = VoxelType::u16;
    BrickLayout l;
    l.brick_size = glm::uvec3(32);
    return BrickHierarchy(v, l);
  }
  ResidencyQuery query() {
    return [this](std::uint32_t s, std::uint32_t l, glm::uvec3 b) {
      return resident[s][hierarchy.linear_index(l, b)] != 0;
    };
  }
  void set(std::uint32_t s, std::uint32_t l, glm::uvec3 b, bool on) {
    resident[s][hierarchy.linear_index(l, b)] = on ? 1 : 0;
  }
};

struct Key {
  std::uint32_t slot;
  std::uint32_t level;
  glm::uvec3 brick;
};

enum class Mode { add_evict, add, evict };

void run(benchmark::State& state, Mode mode) {
  const auto leaf = std::uint32_t(state.range(0));
  const auto slots = std::uint32_t(state.range(1));
  const auto level = std::uint32_t(state.range(2));
  const OctreeLayout layout{glm::u64vec3(extent()), glm::uvec3(leaf)};
  const std::uint64_t bytes = layout.node_count() * ResidencyOctree::bytes_per_node(slots);
  state.counters["nodes"] = double(layout.node_count());
  state.counters["depths"] = double(layout.depth_count());
  state.counters["bytes_per_node"] = double(ResidencyOctree::bytes_per_node(slots));
  state.counters["storage_MiB"] = double(bytes) / double(1 << 20);
  if (bytes > kMaxStorage) {
    state.SkipWithError(("needs " + std::to_string(bytes >> 20) + " MiB of node words").c_str());
    return;
  }
  Setup setup(slots);
  ResidencyOctree tree(setup.hierarchy, layout, slots, setup.query());
  if (level >= setup.hierarchy.level_count()) {
    state.SkipWithError("level past the hierarchy");
    return;
  }

  std::mt19937 rng(42);
  const glm::uvec3 n0 = setup.hierarchy.level(0).bricks;
  for (std::uint32_t s = 0; s < slots; ++s) {
    for (std::uint32_t i = 0; i < n0.x * n0.y * n0.z / 4; ++i) {
      const glm::uvec3 b(rng() % n0.x, rng() % n0.y, rng() % n0.z);
      setup.set(s, 0, b, true);
      tree.brick_added(s, 0, b);
    }
  }
  (void)tree.take_deltas();

  // Bricks of the measured level that are not resident in the background.
  const glm::uvec3 n = setup.hierarchy.level(level).bricks;
  // Distinct bricks of the measured level that are not resident in the background.
  std::vector<Key> keys;
  std::vector<std::uint8_t> taken(setup.hierarchy.bricks_per_channel() * slots, 0);
  const std::size_t want = std::min<std::size_t>(1024, n.x * n.y * n.z * slots / 2);
  while (keys.size() < want) {
    const Key k{std::uint32_t(rng() % slots), level,
                glm::uvec3(rng() % n.x, rng() % n.y, rng() % n.z)};
    const std::size_t id =
        std::size_t(setup.hierarchy.linear_index(level, k.brick)) * slots + k.slot;
    if (taken[id] || setup.query()(k.slot, k.level, k.brick)) continue;
    taken[id] = 1;
    keys.push_back(k);
  }

  auto add = [&](const Key& k) {
    setup.set(k.slot, k.level, k.brick, true);
    tree.brick_added(k.slot, k.level, k.brick);
  };
  auto evict = [&](const Key& k) {
    setup.set(k.slot, k.level, k.brick, false);
    tree.brick_evicted(k.slot, k.level, k.brick);
  };
  std::size_t i = 0;
  std::int64_t items = 0;
  tree.reset_stats();
  // The counters of the measured updates only: in the Add and Evict rows the tree's statistics
  // also count the paused half, whose share is taken out per batch.
  OctreeUpdateStats measured;
  auto count = [&measured](const OctreeUpdateStats& from, const OctreeUpdateStats& to) {
    measured.nodes_visited += to.nodes_visited - from.nodes_visited;
    measured.words_changed += to.words_changed - from.words_changed;
    measured.residency_queries += to.residency_queries - from.residency_queries;
  };
  if (mode == Mode::add_evict) {
    for (auto _ : state) {
      const Key& k = keys[i++ % keys.size()];
      add(k);
      evict(k);
      if (i % 1024 == 0) benchmark::DoNotOptimize(tree.take_deltas());
    }
    items = state.iterations();
    count(OctreeUpdateStats{}, tree.stats());
  } else {
    // Whole batches per half so that PauseTiming's own cost is spread over many bricks.
    for (auto _ : state) {
      const OctreeUpdateStats before_add = tree.stats();
      if (mode == Mode::evict) state.PauseTiming();
      for (const Key& k : keys) add(k);
      if (mode == Mode::evict) state.ResumeTiming();
      const OctreeUpdateStats before_evict = tree.stats();
      if (mode == Mode::add) state.PauseTiming();
      for (const Key& k : keys) evict(k);
      if (mode == Mode::add) state.ResumeTiming();
      if (mode == Mode::add) {
        count(before_add, before_evict);
      } else {
        count(before_evict, tree.stats());
      }
      benchmark::DoNotOptimize(tree.take_deltas());
    }
    items = state.iterations() * std::int64_t(keys.size());
  }
  benchmark::ClobberMemory();
  state.SetItemsProcessed(items);
  state.counters["ns_per_brick"] = benchmark::Counter(
      double(items) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  const double it = double(std::max<std::int64_t>(items, 1));
  state.counters["nodes_visited"] = double(measured.nodes_visited) / it;
  state.counters["words_changed"] = double(measured.words_changed) / it;
  state.counters["queries"] = double(measured.residency_queries) / it;
}

void BM_OctreeAddEvict(benchmark::State& s) {
  run(s, Mode::add_evict);
}
void BM_OctreeAdd(benchmark::State& s) {
  run(s, Mode::add);
}
void BM_OctreeEvict(benchmark::State& s) {
  run(s, Mode::evict);
}

void depth_and_slots(benchmark::internal::Benchmark* b) {
  for (int leaf : {8, 16, 32}) {
    for (int slots : {1, 4, 16}) {
      for (int level : {0, 2, 4}) b->Args({leaf, slots, level});
    }
  }
  b->Args({24, 4, 0});  // leaves not aligned with bricks: eviction asks the residency query
  b->Unit(benchmark::kNanosecond);
}

// What the renderer adds to each level-0 brick upload: exact metadata of the leaves inside the
// brick from its voxels (metadata_from_brick), one slot, u16 voxels: <smooth> 0 = random values
// (every row spans many occupancy bins: the worst case), 1 = a smooth ramp along z.
void BM_OctreeMetadataFromBrick(benchmark::State& state) {
  const auto leaf = std::uint32_t(state.range(0));
  const bool smooth = state.range(1) != 0;
  Setup setup(1);
  ResidencyOctree tree(setup.hierarchy, OctreeLayout{glm::u64vec3(extent()), glm::uvec3(leaf)}, 1,
                       setup.query());
  const std::size_t count = setup.hierarchy.layout().padded_voxels();
  const std::size_t slice = std::size_t(setup.hierarchy.layout().padded_size().x) *
                            setup.hierarchy.layout().padded_size().y;
  std::vector<std::byte> voxels(count * 2);
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < count; ++i) {
    const auto v = std::uint16_t(smooth ? 20000u + 400u * (i / slice) : rng() & 0xffffu);
    std::memcpy(voxels.data() + 2 * i, &v, 2);
  }
  const glm::uvec3 n = setup.hierarchy.level(0).bricks;
  std::uint64_t i = 0;
  for (auto _ : state) {
    const glm::uvec3 b(std::uint32_t(i % n.x), std::uint32_t((i / n.x) % n.y),
                       std::uint32_t((i / n.x / n.y) % n.z));
    tree.metadata_from_brick(0, 0, b, voxels);
    if (++i % 1024 == 0) benchmark::DoNotOptimize(tree.take_deltas());
  }
  state.counters["ns_per_brick"] = benchmark::Counter(
      double(state.iterations()) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// What the renderer's frame thread still does per level-0 upload now that the loader threads
// scan the brick (scan_leaves, outside the timed loop): store the records and propagate them.
void BM_OctreeLeafMetadata(benchmark::State& state) {
  const auto leaf = std::uint32_t(state.range(0));
  Setup setup(1);
  const OctreeLayout layout{glm::u64vec3(extent()), glm::uvec3(leaf)};
  ResidencyOctree tree(setup.hierarchy, layout, 1, setup.query());
  std::vector<std::byte> voxels(setup.hierarchy.layout().padded_voxels() * 2);
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < voxels.size(); i += 2) {
    const auto v = std::uint16_t(rng() & 0xffffu);
    std::memcpy(voxels.data() + i, &v, 2);
  }
  const glm::uvec3 n = setup.hierarchy.level(0).bricks;
  constexpr std::uint64_t kBricks = 256;  // one upload budget's worth, stored in turn
  std::vector<glm::uvec3> bricks;
  std::vector<std::vector<LeafScan>> scans;
  for (std::uint64_t i = 0; i < kBricks; ++i) {
    const glm::uvec3 b(std::uint32_t(i % n.x), std::uint32_t((i / n.x) % n.y),
                       std::uint32_t((i / n.x / n.y) % n.z));
    bricks.push_back(b);
    scans.push_back(scan_leaves(layout, setup.hierarchy, default_range(VoxelType::u16), b, voxels));
  }
  std::uint64_t i = 0;
  for (auto _ : state) {
    tree.leaf_metadata(0, bricks[i % kBricks], scans[i % kBricks]);
    if (++i % 1024 == 0) benchmark::DoNotOptimize(tree.take_deltas());
  }
  state.counters["ns_per_brick"] = benchmark::Counter(
      double(state.iterations()) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_OctreeAddEvict)->Apply(depth_and_slots);
BENCHMARK(BM_OctreeMetadataFromBrick)
    ->ArgsProduct({{8, 16, 32}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OctreeLeafMetadata)->Arg(8)->Arg(16)->Arg(32)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OctreeAdd)->Args({16, 4, 0})->Args({16, 4, 2})->Unit(benchmark::kNanosecond);
BENCHMARK(BM_OctreeEvict)->Args({16, 4, 0})->Args({16, 4, 2})->Unit(benchmark::kNanosecond);

}  // namespace

BENCHMARK_MAIN();
