// Scaling (issue 6 part 5, paper 002 Fig. 5).
//
//   BM_ScreenVsData/size_log2:<k>/fixed_leaf:<f>  one fixed view of procedural:tubes at 2^k
//     voxels per axis;
//     a fresh Renderer (residency mode, global strategy, synchronous loading, backend under test
//     with one render thread) renders from a cold cache until converged, then 3 steady frames. The
//     level-of-detail choice should make the working set follow the screen, not the data:
//     counters working_set_bricks / working_set_MiB (converged frame), ws_growth (working set
//     over that of the smallest size of the run, same process), voxel_growth, frames,
//     ms_to_converge, ms_steady (mean render_frame once converged), bricks_loaded, leaf, and the
//     last frame's samples_per_ray, nodes_per_ray, iterations_per_ray and host phases
//     ms_last_render (frame tables + Backend::render), ms_last_backend (Backend::render alone),
//     ms_last_update, ms_last_requests. Octree leaves:
//     f = 0 grows the leaf with the volume (n / 32, at least 16: 32 leaves per axis at every
//     size, like the screen-bound sampling level); f = 1 keeps 16³ leaves (up to 2048³; larger
//     trees need > 300 MB of node words): nodes_per_ray then grows with the data, because the
//     traversal descends to leaf depth whatever level it samples.
//     Sizes 512³ .. 65536³ (virtual: 2^48 voxels, 2^33 level-0 bricks) with 128² images
//     (standard), 512² (--large); 512³ and 1024³ with 32² (--smoke). The sparse page table
//     (16³-brick blocks from a fixed pool) holds only the blocks the view touches: counters
//     page_blocks (allocated pool blocks), page_table_MiB (host directory + allocated blocks;
//     the directory of 65536³ is 128³ words per slot at level 0) and pool_MiB (device pool
//     capacity).
//     Coarse bricks come from the field with one sample per coarse voxel (samples_log2 = 0): the
//     working set does not depend on how exactly coarse voxels approximate level 0, and the
//     default 64 samples would cost up to 0.2 s per brick.
//
//   BM_Threads/dataset:<d>/threads:<t>  OpenMP efficiency of the CPU backend: everything resident
//     (the rig of bench_table1), residency mode, one orbit; d = 0 tubes, 1 turbulence (256³, 256²
//     image; 48³ / 32² with --smoke). Counters ms_frame (wall), speedup (threads-1 wall time over
//     this row's, same process) and efficiency = speedup / threads. Only the CPU backend has a
//     thread count; other backends skip these rows.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "support/bench_rig.hpp"
#include "support/converge_run.hpp"

namespace {

using namespace resoct;
using namespace resoct::bench;

std::uint32_t screen_image() {
  return preset() == Preset::smoke ? 32u : preset() == Preset::large ? 512u : 128u;
}

void BM_ScreenVsData(benchmark::State& state) {
  // (leaf rule, size_log2) -> working set bricks, this process
  static std::map<std::pair<int, int>, double> ws_by_size;
  const int k = int(state.range(0));
  const bool fixed_leaf = state.range(1) == 1;
  if (fixed_leaf && k > 11) {
    state.SkipWithError("fixed 16^3 leaves above 2048^3 need > 300 MB of octree words");
    return;
  }
  if (preset() == Preset::smoke && k > 10) {
    state.SkipWithError("smoke preset: sizes above 1024^3 skipped");
    return;
  }
  const std::uint64_t n = std::uint64_t(1) << k;
  const std::string spec = "procedural:tubes:" + std::to_string(n) + "x" + std::to_string(n) + "x" +
                           std::to_string(n) + ":1";
  BrickLayout layout;
  layout.brick_size = glm::uvec3(32);
  auto source = std::make_shared<ProceduralSource>(spec, layout, 0);
  RendererOptions o;
  o.backend = backend_name();
  o.backend_options.threads = 1;  // see bench_out_of_core: stable on a shared machine
  o.strategy = RequestStrategy::global;
  o.upload_budget.max_bricks = 1024;
  o.loader_threads = 0;
  o.device_cache_bytes = std::uint64_t(256) << 20;
  o.leaf_size = glm::uvec3(fixed_leaf ? 16u : std::uint32_t(std::max<std::uint64_t>(16, n / 32)));
  const Scene scene = source_scene(source->volume(), 1, screen_image(), false);
  ConvergeRun run;
  for (auto _ : state) {
    run = converge(source, scene, o, 64, 3);
    benchmark::DoNotOptimize(run.image.pixels().data());
  }
  const double ws = double(run.working_set_bricks);
  const int rule = fixed_leaf ? 1 : 0;
  ws_by_size[{rule, k}] = ws;
  const auto first = ws_by_size.lower_bound({rule, 0});
  const int k0 = first->first.second;
  const double ws0 = first->second;
  state.counters["working_set_bricks"] = ws;
  state.counters["working_set_MiB"] = double(run.working_set_bytes) / double(1 << 20);
  state.counters["ws_growth"] = ws0 > 0 ? ws / ws0 : 0.0;
  state.counters["voxel_growth"] = std::pow(8.0, double(k - k0));
  state.counters["frames"] = run.frames;
  state.counters["converged"] = run.converged ? 1 : 0;
  state.counters["ms_to_converge"] = run.ms_total;
  state.counters["ms_steady"] = run.ms_steady;
  state.counters["bricks_loaded"] = double(run.bricks_loaded);
  state.counters["leaf"] = o.leaf_size.x;
  state.counters["page_blocks"] = run.page_blocks;
  state.counters["page_table_MiB"] = double(run.page_table_bytes) / double(1 << 20);
  state.counters["pool_MiB"] =
      double(run.page_pool_blocks) * kernel::RESOCT_PAGE_BLOCK_ENTRIES * 4.0 / double(1 << 20);
  const BackendStats& b = run.last.backend;
  const double rays = double(std::max<std::uint64_t>(b.rays, 1));
  state.counters["samples_per_ray"] = double(b.samples) / rays;
  state.counters["nodes_per_ray"] = double(b.nodes_visited) / rays;
  state.counters["iterations_per_ray"] = double(b.iterations) / rays;
  // Where a steady frame's time goes (host wall ms of the last frame's phases).
  state.counters["ms_last_render"] = run.last.ms_render;
  state.counters["ms_last_backend"] = b.ms_render;
  state.counters["ms_last_update"] = run.last.ms_update;
  state.counters["ms_last_requests"] = run.last.ms_requests;
  state.SetLabel(std::to_string(n) + "^3/leaf " + std::to_string(o.leaf_size.x));
}

BENCHMARK(BM_ScreenVsData)
    ->ArgsProduct({benchmark::CreateDenseRange(9, 16, 1), {0, 1}})
    ->ArgNames({"size_log2", "fixed_leaf"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

constexpr const char* kThreadNames[] = {"tubes", "turbulence"};

void BM_Threads(benchmark::State& state) {
  static std::map<int, double> one_thread;  // dataset -> ms/frame with 1 thread
  const int d = int(state.range(0));
  const int threads = int(state.range(1));
  if (backend_name() != "cpu") {
    state.SkipWithError("thread scaling is measured on the CPU backend only");
    return;
  }
  const char* size = preset() == Preset::smoke   ? "48x48x48"
                     : preset() == Preset::large ? "512x512x512"
                                                 : "256x256x256";
  // One resident rig per dataset; a thread count only needs a new backend.
  static int key = -1;
  static std::unique_ptr<Rig> rig_ptr;
  if (!rig_ptr || key != d) {
    rig_ptr.reset();
    rig_ptr = std::make_unique<Rig>(
        std::string("procedural:") + kThreadNames[d] + ":" + size + ":1",
        std::vector<std::uint32_t>{0}, glm::uvec3(32), glm::uvec3(16), 0, threads);
    key = d;
  } else {
    rig_ptr->backend = make_backend(threads);
    rig_ptr->resident->upload(*rig_ptr->backend);
  }
  Rig& rig = *rig_ptr;
  const std::uint32_t image = preset() == Preset::smoke   ? 32u
                              : preset() == Preset::large ? 512u
                                                          : 256u;
  const Scene scene = bench_scene(rig, 1, image);
  const auto tables = orbit_tables(rig, scene, RenderMode::residency, orbit_frames());
  const FrameAverages a = run_frames(state, rig, tables);
  if (threads == 1) one_thread[d] = a.ms_frame;
  const auto it = one_thread.find(d);
  if (it != one_thread.end()) {
    state.counters["speedup"] = it->second / a.ms_frame;
    state.counters["efficiency"] = it->second / a.ms_frame / double(threads);
  }
  state.SetLabel(std::string(kThreadNames[d]) + "/" + std::to_string(threads) + " thread" +
                 (threads > 1 ? "s" : ""));
}

BENCHMARK(BM_Threads)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->ArgNames({"dataset", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return resoct::bench::run_benchmarks(argc, argv);
}
