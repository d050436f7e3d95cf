// Brick store throughput: reading + checksumming + decompressing bricks (MB/s of uncompressed
// voxels), and writing whole stores, for LZ4 and zstd. Volumes: a smooth, sparse one and a noisy
// one from a small generator defined here (precomputed, so write benchmarks time the store, not
// the generator), and three of resoct's procedural datasets (tubes, turbulence, cells), whose
// read benchmarks report the compression ratio real data of that kind gets.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>

#include <unistd.h>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/sources/procedural_source.hpp"

using namespace resoct;

namespace {

enum class Kind : int { smooth_sparse = 0, noisy = 1, tubes = 2, turbulence = 3, cells = 4 };

const char* procedural_spec(Kind kind) {
  switch (kind) {
    case Kind::tubes: return "procedural:tubes:256x256x256";
    case Kind::turbulence: return "procedural:turbulence:256x256x256";
    case Kind::cells: return "procedural:cells:256x256x40:16";
    default: return nullptr;
  }
}
constexpr std::uint64_t kExtent = 192;

double smooth_sparse(double x, double y, double z) {
  // A few soft blobs in an otherwise empty volume, like a segmented specimen.
  static const double centers[4][4] = {
      {50, 60, 70, 18}, {130, 120, 60, 24}, {90, 150, 140, 14}, {150, 40, 150, 20}};
  double v = 0.0;
  for (const auto& c : centers) {
    const double d2 = (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2]);
    v += std::exp(-d2 / (2.0 * c[3] * c[3]));
  }
  return v < 0.05 ? 0.0 : std::min(1.0, v) * 65535.0;
}

double noisy(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  std::uint64_t h =
      x * 0x9E3779B97F4A7C15ull ^ y * 0xC2B2AE3D27D4EB4Full ^ z * 0x165667B19E3779F9ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  // Signal plus 10 bits of noise: roughly what a raw microscope or CT volume looks like.
  return double((x + y + z) * 100 % 60000) + double(h & 0x3FFu);
}

// All bricks precomputed, so that write benchmarks time the store, not the generator.
class GeneratedSource final : public BrickSource {
 public:
  explicit GeneratedSource(Kind kind) : h_(desc(), BrickLayout{glm::uvec3(32), 1}) {
    const std::size_t n = h_.layout().padded_voxels();
    bricks_.resize(std::size_t(h_.bricks_per_channel()));
    for (std::uint64_t i = 0; i < h_.bricks_per_channel(); ++i) {
      const BrickKey k = h_.key_from_linear(0, i);
      const LevelInfo& li = h_.level(k.level());
      const Box3 box = h_.padded_box(k.level(), k.brick());
      std::vector<std::uint16_t>& out = bricks_[std::size_t(i)];
      out.reserve(n);
      for (std::int64_t z = box.lo.z; z < box.hi.z; ++z) {
        for (std::int64_t y = box.lo.y; y < box.hi.y; ++y) {
          for (std::int64_t x = box.lo.x; x < box.hi.x; ++x) {
            const glm::i64vec3 p = glm::clamp(glm::i64vec3(x, y, z), glm::i64vec3(0),
                                              glm::i64vec3(li.extent) - std::int64_t(1));
            const glm::u64vec3 p0 = glm::u64vec3(p) << glm::u64vec3(li.factor_log2);
            const double v = kind == Kind::noisy
                                 ? noisy(p0.x, p0.y, p0.z)
                                 : smooth_sparse(double(p0.x), double(p0.y), double(p0.z));
            out.push_back(std::uint16_t(v));
          }
        }
      }
    }
  }
  const BrickHierarchy& hierarchy() const override { return h_; }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    check_brick_request(key, out);
    const auto& b = bricks_[std::size_t(h_.linear_index(key.level(), key.brick()))];
    std::memcpy(out.data(), b.data(), out.size());
  }
  RegionMeta region_meta(std::uint32_t, const Box3&) const override {
    // Never queried by the writer; the full range is the conservative answer.
    return RegionMeta{0.0, 65535.0, occupancy_span(0.0, 65535.0, volume().range(0))};
  }
  std::string name() const override { return "bench-generated"; }

 private:
  static VolumeDesc desc() {
    VolumeDesc v;
    v.extent = glm::u64vec3(kExtent);
    v.type = VoxelType::u16;
    return v;
  }
  BrickHierarchy h_;
  std::vector<std::vector<std::uint16_t>> bricks_;
};

std::filesystem::path bench_dir() {
  static const struct Dir {
    std::filesystem::path path;
    Dir() {
      path = std::filesystem::temp_directory_path() /
             ("resoct-bench-store-" + std::to_string(::getpid()));
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

const BrickSource& source(Kind kind) {
  static std::mutex m;
  static std::map<Kind, std::unique_ptr<BrickSource>> cache;
  const std::lock_guard<std::mutex> g(m);
  auto& s = cache[kind];
  if (!s) {
    if (const char* spec = procedural_spec(kind)) {
      s = make_procedural_source(spec);
    } else {
      s = std::make_unique<GeneratedSource>(kind);
    }
  }
  return *s;
}

struct Written {
  std::string path;
  StoreSummary summary;
};

// One store per (codec, kind), written on first use and shared by all read benchmarks.
const Written& store(Codec codec, Kind kind) {
  static std::mutex m;
  static std::map<std::pair<Codec, Kind>, Written> cache;
  const std::lock_guard<std::mutex> g(m);
  const auto key = std::make_pair(codec, kind);
  auto it = cache.find(key);
  if (it == cache.end()) {
    Written w;
    w.path =
        (bench_dir() / (std::string(to_string(codec)) + "-" + std::to_string(int(kind)) + ".rbs"))
            .string();
    w.summary = write_brick_store(source(kind), w.path, StoreWriteOptions{codec});
    it = cache.emplace(key, std::move(w)).first;
  }
  return it->second;
}

std::string label(Codec codec, Kind kind) {
  const char* names[] = {"smooth_sparse", "noisy", "tubes", "turbulence", "cells"};
  return std::string(to_string(codec)) + "/" + names[int(kind)];
}

// Reads every level-0 brick of the store once per iteration (each thread its own pass).
void BM_StoreRead(benchmark::State& state) {
  const Codec codec = Codec(state.range(0));
  const Kind kind = Kind(state.range(1));
  const Written& w = store(codec, kind);
  static std::mutex m;
  static std::map<std::string, std::unique_ptr<BrickStoreSource>> open;
  const BrickStoreSource* src = nullptr;
  {
    const std::lock_guard<std::mutex> g(m);
    auto& s = open[w.path];
    if (!s) s = std::make_unique<BrickStoreSource>(w.path);
    src = s.get();
  }
  const BrickHierarchy& h = src->hierarchy();
  std::vector<std::byte> buf(h.layout().padded_voxels() * voxel_size(h.volume().type));
  const LevelInfo& l0 = h.level(0);
  for (auto _ : state) {
    for (std::uint64_t i = 0; i < l0.brick_count; ++i) {
      src->read_brick(h.key_from_linear(0, i), buf);
      benchmark::DoNotOptimize(buf.data());
      benchmark::ClobberMemory();
    }
  }
  state.SetBytesProcessed(std::int64_t(state.iterations() * l0.brick_count * buf.size()));
  state.SetItemsProcessed(std::int64_t(state.iterations() * l0.brick_count));
  const StoreLevelStats& s0 = w.summary.stats.levels[0];
  // Averaged over threads: these describe the file, not the work done.
  state.counters["ratio_l0"] =
      benchmark::Counter(s0.compression_ratio(), benchmark::Counter::kAvgThreads);
  state.counters["empty_frac_l0"] =
      benchmark::Counter(s0.empty_fraction(), benchmark::Counter::kAvgThreads);
  state.counters["ratio_all"] = benchmark::Counter(w.summary.stats.total().compression_ratio(),
                                                   benchmark::Counter::kAvgThreads);
  state.SetLabel(label(codec, kind));
}

// Writes a whole store (all levels) per iteration: compress, checksum, write, fsync, rename.
void BM_StoreWrite(benchmark::State& state) {
  const Codec codec = Codec(state.range(0));
  const Kind kind = Kind(state.range(1));
  const BrickSource& src = source(kind);
  const std::string path = (bench_dir() / "write.rbs").string();
  StoreWriteOptions opt;
  opt.codec = codec;
  opt.threads = std::uint32_t(state.range(2));
  StoreSummary last;
  for (auto _ : state) {
    last = write_brick_store(src, path, opt);
    benchmark::DoNotOptimize(last);
  }
  const StoreLevelStats total = last.stats.total();
  state.SetBytesProcessed(std::int64_t(state.iterations() * total.uncompressed_bytes));
  state.SetItemsProcessed(std::int64_t(state.iterations() * total.brick_count));
  state.counters["ratio"] = total.compression_ratio();
  state.counters["file_MB"] = double(last.stats.file_bytes) / 1e6;
  state.SetLabel(label(codec, kind));
}

void read_args(benchmark::internal::Benchmark* b) {
  for (const int codec : {0, 1}) {
    for (const int kind : {0, 1, 2, 3, 4}) b->Args({codec, kind});
  }
}
void write_args(benchmark::internal::Benchmark* b) {
  for (const int codec : {0, 1}) {
    for (const int kind : {0, 1}) {
      for (const int threads : {1, 2}) b->Args({codec, kind, threads});
    }
  }
}

BENCHMARK(BM_StoreRead)
    ->Apply(read_args)
    ->ArgNames({"codec", "kind"})
    ->Threads(1)
    ->Threads(2)
    ->UseRealTime();
BENCHMARK(BM_StoreWrite)
    ->Apply(write_args)
    ->ArgNames({"codec", "kind", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
