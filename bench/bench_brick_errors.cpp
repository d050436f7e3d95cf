// What a coarse brick's down-sampling error costs (BrickSource::brick_error, the value
// error-bounded LOD chooses levels by; docs/rendering.md "Error-bounded LOD"), per kind of
// source, and what storing the errors costs a conversion.
//
// BM_BrickError/source:S: one pass over every coarse brick (levels >= 1, both channels) of a
// 256³ u8 volume of 32³ bricks, asking the source for the brick's error; the padded voxels are
// read before the timed loop (the loader has them anyway). S:
//   0 memory     InMemorySource: measured, level-0 bricks copied from memory (the cheapest
//                measurement)
//   1 store      a brick store without errors: measured, level-0 bricks read, checked and
//                decompressed from the file (what a store converted without --brick-errors costs)
//   2 stored     a brick store written with errors: read from its errors section
//   3 pyramid    PyramidSource (OME-Zarr, NIfTI, NRRD, TIFF): measured once, then cached; the
//                timed passes after the first hit the cache
// Counters: bricks (per pass), ns_per_brick (CPU time per brick), level0_reads (per pass).
//
// BM_StoreWriteErrors/errors:E: write_brick_store of the same volume without (0) and with (1)
// StoreWriteOptions::brick_errors, 2 threads; counter seconds_per_store (process CPU time).

#include <benchmark/benchmark.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <vector>

#include <unistd.h>

#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/sources/in_memory_source.hpp"

using namespace resoct;

namespace {

std::uint64_t extent() {
  // The smoke run (ctest label bench-smoke) only checks that the program works.
  return std::getenv("RESOCT_BENCH_SMOKE") != nullptr ? 64 : 256;
}

// Two channels: smooth waves with a sharp spherical edge (some bricks coarsen, some do not), and
// the waves alone in the lower half, zero above (empty space, answered from metadata).
DenseVolume volume() {
  const std::uint64_t n = extent();
  VolumeDesc d;
  d.extent = glm::u64vec3(n);
  d.channels = 2;
  d.type = VoxelType::u8;
  std::vector<std::uint8_t> v(std::size_t(n * n * n * 2));
  std::size_t i = 0;
  for (std::uint32_t c = 0; c < 2; ++c) {
    for (std::uint64_t z = 0; z < n; ++z) {
      for (std::uint64_t y = 0; y < n; ++y) {
        for (std::uint64_t x = 0; x < n; ++x, ++i) {
          const double s = double(n) / 256.0;
          const double waves = 0.5 + 0.45 * std::sin(double(x) / (9.0 * s)) *
                                         std::sin(double(y) / (7.0 * s)) *
                                         std::sin(double(z) / (11.0 * s));
          const double dx = double(x) - 0.5 * double(n), dy = double(y) - 0.5 * double(n),
                       dz = double(z) - 0.5 * double(n);
          const bool inside = dx * dx + dy * dy + dz * dz < 0.16 * double(n * n);
          const double value = c == 0 ? (inside ? waves : 0.2 * waves) : (z < n / 2 ? waves : 0.0);
          v[i] = std::uint8_t(std::lround(255.0 * value));
        }
      }
    }
  }
  return DenseVolume::from_values(d, v);
}

BrickLayout layout() {
  return BrickLayout{glm::uvec3(32), 1};
}

// Counts level-0 reads of an inner source (the measurement's cost driver).
class CountingReads final : public BrickSource {
 public:
  explicit CountingReads(std::shared_ptr<const BrickSource> inner) : inner_(std::move(inner)) {}
  const BrickHierarchy& hierarchy() const override { return inner_->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    if (key.level() == 0) reads.fetch_add(1, std::memory_order_relaxed);
    inner_->read_brick(key, out);
  }
  BrickMeta brick_meta(BrickKey key) const override { return inner_->brick_meta(key); }
  double brick_error(BrickKey key, std::span<const std::byte> padded) const override {
    // The inner source's own answer (stored, cached or measured through this wrapper's reads).
    if (measures_here) return BrickSource::brick_error(key, padded);
    return inner_->brick_error(key, padded);
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_->region_meta(c, b);
  }
  std::string name() const override { return inner_->name(); }

  bool measures_here = false;  // measure through read_brick (counted) instead of asking inner
  mutable std::atomic<std::uint64_t> reads{0};

 private:
  std::shared_ptr<const BrickSource> inner_;
};

struct Fixture {
  std::filesystem::path dir;
  std::shared_ptr<const BrickSource> memory, store, stored;
  std::shared_ptr<const PyramidSource> pyramid;

  Fixture() {
    dir = std::filesystem::temp_directory_path() /
          ("resoct-bench-errors-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    memory = std::make_shared<InMemorySource>(volume(), layout());
    StoreWriteOptions o;
    o.threads = 2;
    write_brick_store(*memory, (dir / "plain.rbs").string(), o);
    o.brick_errors = true;
    write_brick_store(*memory, (dir / "errors.rbs").string(), o);
    store = std::make_shared<BrickStoreSource>((dir / "plain.rbs").string());
    stored = std::make_shared<BrickStoreSource>((dir / "errors.rbs").string());
    pyramid = make_dense_pyramid_source(volume(), layout(), "pyramid");
  }
  ~Fixture() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void BM_BrickError(benchmark::State& state) {
  Fixture& fx = fixture();
  const int kind = int(state.range(0));
  std::shared_ptr<const BrickSource> inner = kind == 0   ? fx.memory
                                             : kind == 1 ? fx.store
                                             : kind == 2 ? fx.stored
                                                         : fx.pyramid;
  CountingReads src(inner);
  // Sources without their own answer measure through the wrapper, so that their reads count.
  src.measures_here = kind <= 1;
  const BrickHierarchy& h = src.hierarchy();
  const std::size_t brick_bytes = h.layout().padded_voxels();
  std::vector<BrickKey> keys;
  std::vector<std::vector<std::byte>> voxels;
  for (std::uint32_t c = 0; c < h.volume().channels; ++c) {
    for (std::uint32_t l = 1; l < h.level_count(); ++l) {
      for (std::uint64_t i = 0; i < h.level(l).brick_count; ++i) {
        keys.push_back(h.key_from_linear(c, h.level(l).first_brick + i));
        voxels.emplace_back(brick_bytes);
        inner->read_brick(keys.back(), voxels.back());
      }
    }
  }
  double sum = 0.0;
  if (kind == 3) {  // the cache's first fill is not what the rows after it cost
    for (std::size_t k = 0; k < keys.size(); ++k) sum += src.brick_error(keys[k], voxels[k]);
  }
  src.reads = 0;
  std::uint64_t passes = 0;
  for (auto _ : state) {
    for (std::size_t k = 0; k < keys.size(); ++k) sum += src.brick_error(keys[k], voxels[k]);
    ++passes;
  }
  benchmark::DoNotOptimize(sum);
  state.counters["bricks"] = double(keys.size());
  state.counters["ns_per_brick"] =
      benchmark::Counter(double(keys.size()) * 1e-9, benchmark::Counter::kIsIterationInvariantRate |
                                                         benchmark::Counter::kInvert);
  state.counters["level0_reads"] = passes == 0 ? 0.0 : double(src.reads.load()) / double(passes);
  static const char* names[] = {"memory", "store", "stored", "pyramid"};
  state.SetLabel(names[kind]);
}

void BM_StoreWriteErrors(benchmark::State& state) {
  Fixture& fx = fixture();
  StoreWriteOptions o;
  o.threads = 2;
  o.brick_errors = state.range(0) != 0;
  const std::string path = (fx.dir / "bench.rbs").string();
  for (auto _ : state) write_brick_store(*fx.memory, path, o);
  state.counters["seconds_per_store"] = benchmark::Counter(
      1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_BrickError)->ArgName("source")->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
// The writer's worker threads do the work: CPU time is the process's.
BENCHMARK(BM_StoreWriteErrors)
    ->ArgName("errors")
    ->DenseRange(0, 1)
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
