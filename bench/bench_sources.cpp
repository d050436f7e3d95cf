// Brick supply throughput: procedural brick generation per dataset at level 0, at the deepest
// exact level and at the coarsest (approximated) level, and InMemorySource brick copies.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "resoct/sources/in_memory_source.hpp"
#include "resoct/sources/procedural_source.hpp"

using namespace resoct;

namespace {

const char* const kDatasets[] = {"tubes", "noisefloor", "turbulence", "mandelbulb",
                                 "cells", "constant",   "ramp",       "sphere"};

enum class Which { level0, exact, coarsest };

std::uint32_t pick_level(const ProceduralSource& src, Which w) {
  const std::uint32_t n = src.hierarchy().level_count();
  if (w == Which::level0) return 0;
  if (w == Which::coarsest) return n - 1;
  std::uint32_t l = 0;
  while (l + 1 < n && src.exact_level(l + 1)) ++l;
  return l;
}

// Reads a seeded pseudo-random sequence of bricks of one level (and channel 0), so that sparse
// datasets are measured over their mix of empty and occupied bricks.
void read_bricks(benchmark::State& state, const BrickSource& src, std::uint32_t level) {
  const LevelInfo& li = src.hierarchy().level(level);
  const std::size_t bytes =
      src.hierarchy().layout().padded_voxels() * voxel_size(src.volume().type);
  std::vector<std::byte> buf(bytes);
  std::mt19937_64 rng(42);
  for (auto _ : state) {
    const glm::uvec3 b(std::uint32_t(rng() % li.bricks.x), std::uint32_t(rng() % li.bricks.y),
                       std::uint32_t(rng() % li.bricks.z));
    src.read_brick(BrickKey(level, 0, b), buf);
    benchmark::DoNotOptimize(buf.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(bytes));
  state.SetItemsProcessed(std::int64_t(state.iterations()) *
                          std::int64_t(src.hierarchy().layout().padded_voxels()));
  state.counters["level"] = double(level);
}

void BM_ProceduralBrick(benchmark::State& state, std::string spec, Which which,
                        std::uint32_t samples_log2) {
  const ProceduralSource src(spec, BrickLayout{}, samples_log2);
  read_bricks(state, src, pick_level(src, which));
}

void BM_ProceduralRegionMeta(benchmark::State& state, std::string spec) {
  const ProceduralSource src(spec);
  const glm::i64vec3 e(src.volume().extent);
  std::mt19937_64 rng(7);
  for (auto _ : state) {
    // Brick-sized regions (32³ level-0 voxels) anywhere in the volume.
    glm::i64vec3 lo;
    for (int a = 0; a < 3; ++a) lo[a] = std::int64_t(rng() % std::uint64_t(e[a]));
    benchmark::DoNotOptimize(src.region_meta(0, Box3{lo, lo + glm::i64vec3(32)}));
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}

void BM_InMemoryReadBrick(benchmark::State& state) {
  const VoxelType t = VoxelType(state.range(0));
  VolumeDesc d;
  d.extent = glm::u64vec3(256);
  d.type = t;
  std::vector<std::byte> data(std::size_t(d.voxel_count()) * voxel_size(t));
  std::mt19937 rng(3);
  for (std::byte& b : data) b = std::byte(rng() & 0x3f);  // small values: finite for f32
  const InMemorySource src(DenseVolume::from_bytes(d, std::move(data)));
  read_bricks(state, src, 0);
  state.SetLabel(std::string(to_string(t)));
}

const int kRegistered = [] {
  for (const char* name : kDatasets) {
    const std::string spec = std::string("procedural:") + name;
    benchmark::RegisterBenchmark(("BM_ProceduralBrick/" + std::string(name) + "/level0").c_str(),
                                 BM_ProceduralBrick, spec, Which::level0, 2u)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_ProceduralBrick/" + std::string(name) + "/exact").c_str(),
                                 BM_ProceduralBrick, spec, Which::exact, 2u)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_ProceduralBrick/" + std::string(name) + "/coarsest").c_str(),
                                 BM_ProceduralBrick, spec, Which::coarsest, 2u)
        ->Unit(benchmark::kMicrosecond);
    // The cheaper coarse-level setting (8 instead of 64 samples per voxel) for comparison.
    benchmark::RegisterBenchmark(
        ("BM_ProceduralBrick/" + std::string(name) + "/coarsest_samples_log2_1").c_str(),
        BM_ProceduralBrick, spec, Which::coarsest, 1u)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_ProceduralRegionMeta/" + std::string(name)).c_str(),
                                 BM_ProceduralRegionMeta, spec)
        ->Unit(benchmark::kMicrosecond);
  }
  return 0;
}();

}  // namespace

BENCHMARK(BM_InMemoryReadBrick)
    ->Arg(int(VoxelType::u8))
    ->Arg(int(VoxelType::u16))
    ->Arg(int(VoxelType::f32))
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
