// HTTP vs local read throughput on loopback: brick store reads (read + checksum + decompress of
// every level-0 brick, MB/s of decoded voxels and of payload bytes moved) and raw range reads
// (MB/s of bytes moved), each from the local file (pread) and from tests/support's Python HTTP
// server on 127.0.0.1 (HttpStore Range requests over keep-alive connections). The server is
// single-process Python, so the HTTP numbers bound what a loopback request costs with a slow
// server, not what libcurl can do. RESOCT_BENCH_SMOKE=1 shrinks the volume.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>

#include <unistd.h>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/http/http_store.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/io/http/open_random_access_file.hpp"
#include "support/http_test_server.hpp"

using namespace resoct;

namespace {

bool smoke() {
  const char* s = std::getenv("RESOCT_BENCH_SMOKE");
  return s && std::string(s) == "1";
}

/// One store and one server for the whole program (removed at exit).
struct Fixture {
  std::filesystem::path dir;
  std::unique_ptr<test::HttpTestServer> server;
  std::uint64_t file_bytes = 0;

  Fixture() {
    dir = std::filesystem::temp_directory_path() /
          ("resoct-bench-http-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const char* spec =
        smoke() ? "procedural:turbulence:64x64x64" : "procedural:turbulence:256x256x256";
    const auto src = make_procedural_source(spec, BrickLayout{glm::uvec3(32), 1});
    write_brick_store(*src, (dir / "vol.rbs").string());
    file_bytes = std::filesystem::file_size(dir / "vol.rbs");
    server = std::make_unique<test::HttpTestServer>(test::HttpTestServer::default_script(),
                                                    dir.string());
  }
  ~Fixture() {
    server.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  std::string local() const { return (dir / "vol.rbs").string(); }
  std::string url() const { return server->base("ok") + "/vol.rbs"; }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

// Arg 0: 0 = local file, 1 = HTTP. Every level-0 brick per iteration, split over the threads.
void BM_StoreRead(benchmark::State& state) {
  static std::mutex m;
  static std::unique_ptr<BrickStoreSource> sources[2];
  const int where = int(state.range(0));
  {
    std::lock_guard lock(m);
    if (!sources[where]) {
      sources[where] = std::make_unique<BrickStoreSource>(
          open_random_access_file(where == 0 ? fixture().local() : fixture().url()));
    }
  }
  const BrickStoreSource& src = *sources[where];
  const BrickHierarchy& h = src.hierarchy();
  std::vector<std::byte> buf(h.layout().padded_voxels() * voxel_size(h.volume().type));
  const LevelInfo& l0 = h.level(0);
  std::uint64_t payload = 0, bricks = 0;
  for (auto _ : state) {
    for (std::uint64_t i = std::uint64_t(state.thread_index()); i < l0.brick_count;
         i += std::uint64_t(state.threads())) {
      src.read_brick(h.key_from_linear(0, i), buf);
      benchmark::DoNotOptimize(buf.data());
      benchmark::ClobberMemory();
      ++bricks;
    }
  }
  const StoreLevelStats& s0 = src.stats().levels[0];
  payload = bricks * s0.compressed_bytes / std::max<std::uint64_t>(1, s0.brick_count);
  state.SetBytesProcessed(std::int64_t(bricks * buf.size()));
  state.SetItemsProcessed(std::int64_t(bricks));
  state.counters["payload_bytes_per_second"] =
      benchmark::Counter(double(payload), benchmark::Counter::kIsRate);
  state.SetLabel(where == 0 ? "local" : "http");
}

// Raw positional reads of `chunk` bytes walking through the file.
void BM_RangeRead(benchmark::State& state) {
  const int where = int(state.range(0));
  // The smoke preset's file is small; a chunk never exceeds half of it.
  const std::uint64_t chunk =
      std::min<std::uint64_t>(std::uint64_t(state.range(1)), fixture().file_bytes / 2);
  static std::mutex m;
  static std::unique_ptr<RandomAccessFile> files[2];
  {
    std::lock_guard lock(m);
    if (!files[where]) {
      files[where] = open_random_access_file(where == 0 ? fixture().local() : fixture().url());
    }
  }
  const RandomAccessFile& f = *files[where];
  std::vector<std::byte> buf(chunk);
  const std::uint64_t span = f.size() - chunk;
  std::uint64_t offset = std::uint64_t(state.thread_index()) * 7919 % span, bytes = 0;
  for (auto _ : state) {
    f.read_at(offset, buf);
    benchmark::DoNotOptimize(buf.data());
    bytes += chunk;
    offset = (offset + chunk * 3 + 4096) % span;
  }
  state.SetBytesProcessed(std::int64_t(bytes));
  state.SetLabel(where == 0 ? "local" : "http");
}

}  // namespace

BENCHMARK(BM_StoreRead)->ArgName("http")->Arg(0)->Arg(1)->Threads(1)->Threads(2)->UseRealTime();
BENCHMARK(BM_RangeRead)
    ->ArgNames({"http", "chunk"})
    ->Args({0, 64 << 10})
    ->Args({1, 64 << 10})
    ->Args({0, 1 << 20})
    ->Args({1, 1 << 20})
    ->UseRealTime();

BENCHMARK_MAIN();
