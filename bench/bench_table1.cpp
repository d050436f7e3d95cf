// Paper 000 Table 1 analogue: the three render modes side by side on the procedural analogues of
// the paper's datasets, everything resident (every level of every loaded channel), camera
// rotating about the up axis (one benchmark iteration = one orbit of 2 / 4 / 16 positions for
// smoke / standard / large; ms_frame is per frame). Backend: CPU on one thread, or the one named
// by RESOCT_BENCH_BACKEND / --backend=NAME (e.g. vulkan).
// Timed: Backend::render alone (the frame tables are built beforehand), so ms/frame is the
// traversal's cost.
//
//   BM_Table1/dataset:<d>/channels:<c>/mode:<m>
//     d = 0 tubes (sparse, ~ Kingsnake), 1 noisefloor (sparse blobs on a transparent noise floor,
//         ~ Beechnut / neurons), 2 turbulence (dense, ~ Rayleigh-Taylor), 3 mandelbulb,
//         4 cells (thin multi-channel slab, ~ CyCIF)
//     c = visible channels: 1 and 4 (16 for cells). As in the paper, the 4-channel rows of the
//         single-channel datasets (0-3) duplicate channel 0 four times (DuplicateChannelSource)
//         and render copy k with its own transfer function (duplicate_tf: transparent below
//         0.1 + 0.125 k); cells has 16 distinct marker channels of its own.
//     m = 1 pagetable, 2 octree, 0 residency (run in this order, so the residency run can
//         report its ratios against the other two from the same process)
// Counters: ms_frame, working_set_MiB (distinct bricks sampled per frame × padded brick bytes),
// samples_per_ray, nodes_per_ray, bricks_touched, brick_accesses_per_ray; on residency rows
// also res_over_pt / res_over_oct (ms) and ws_res_over_pt / ws_res_over_oct (working set).
//
//   BM_SkipMinSamples/dataset:<d>/k:<k>
//     the residency rows of one channel with TuningOptions::skip_min_samples = k (docs/rendering.md
//     "Visible subtrees"): 0, where the descent looks below every node that hides anything, and
//     the default; k_over_0 is ms against the k = 0 row of the same process.
// Octree leaves 16³, or RESOCT_BENCH_LEAF³ (e.g. RESOCT_BENCH_LEAF=32).
// Sizes: 256³ and 512×512×40 with 256² images (standard), 1024³ and 1024×1024×40 with 512²
// (--large or RESOCT_BENCH_LARGE=1), 48³ and 64×64×40 with 32² (--smoke or
// RESOCT_BENCH_SMOKE=1).
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "support/bench_rig.hpp"

namespace {

using namespace resoct;
using namespace resoct::bench;

constexpr const char* kNames[] = {"tubes", "noisefloor", "turbulence", "mandelbulb", "cells"};

std::string spec_for(int dataset) {
  const Preset p = preset();
  if (dataset == 4) {
    const char* size = p == Preset::smoke   ? "64x64x40"
                       : p == Preset::large ? "1024x1024x40"
                                            : "512x512x40";
    return std::string("procedural:cells:") + size + ":16";
  }
  const char* size = p == Preset::smoke   ? "48x48x48"
                     : p == Preset::large ? "1024x1024x1024"
                                          : "256x256x256";
  return std::string("procedural:") + kNames[dataset] + ":" + size + ":1";
}

std::uint32_t image_size() {
  return preset() == Preset::smoke ? 32u : preset() == Preset::large ? 512u : 256u;
}

// Octree leaf edge: 16 unless RESOCT_BENCH_LEAF says otherwise (the leaf study of
// bench_decoupling, applied to the Table 1 datasets).
std::uint32_t leaf_edge() {
  const char* v = std::getenv("RESOCT_BENCH_LEAF");
  const long n = v != nullptr ? std::strtol(v, nullptr, 10) : 0;
  return n >= 1 && n <= 4096 ? std::uint32_t(n) : 16u;
}

// One rig at a time (benchmarks run dataset by dataset), so memory stays that of the largest
// single dataset.
Rig& rig_for(int dataset) {
  static int key = -1;
  static std::unique_ptr<Rig> rig;
  if (!rig || key != dataset) {
    rig.reset();
    const std::uint32_t n = dataset == 4 ? 16u : 4u;
    std::vector<std::uint32_t> channels;
    for (std::uint32_t c = 0; c < n; ++c) channels.push_back(c);
    rig = std::make_unique<Rig>(spec_for(dataset), channels, glm::uvec3(32),
                                glm::uvec3(leaf_edge()), dataset == 4 ? 0u : n);
    key = dataset;
  }
  return *rig;
}

void BM_Table1(benchmark::State& state) {
  static std::map<std::tuple<int, int, int>, FrameAverages> done;
  const int dataset = int(state.range(0));
  const int channels = int(state.range(1));
  const auto mode = RenderMode(std::uint32_t(state.range(2)));
  Rig& rig = rig_for(dataset);
  const Scene scene = bench_scene(rig, std::uint32_t(channels), image_size());
  const auto tables = orbit_tables(rig, scene, mode, orbit_frames());
  const FrameAverages a = run_frames(state, rig, tables);
  done[{dataset, channels, int(mode)}] = a;
  if (mode == RenderMode::residency) {
    const auto pt = done.find({dataset, channels, int(RenderMode::pagetable)});
    const auto oct = done.find({dataset, channels, int(RenderMode::octree)});
    if (pt != done.end()) {
      state.counters["res_over_pt"] = a.ratio_ms() / pt->second.ratio_ms();
      state.counters["ws_res_over_pt"] = a.working_set_bytes / pt->second.working_set_bytes;
    }
    if (oct != done.end()) {
      state.counters["res_over_oct"] = a.ratio_ms() / oct->second.ratio_ms();
      state.counters["ws_res_over_oct"] = a.working_set_bytes / oct->second.working_set_bytes;
    }
  }
  state.SetLabel(std::string(kNames[dataset]) + "/" + to_string(mode));
}

void BM_SkipMinSamples(benchmark::State& state) {
  static std::map<int, FrameAverages> without;
  const int dataset = int(state.range(0));
  const int k = int(state.range(1));
  Rig& rig = rig_for(dataset);
  const Scene scene = bench_scene(rig, 1u, image_size());
  const auto tables = orbit_tables(rig, scene, RenderMode::residency, orbit_frames(), float(k));
  const FrameAverages a = run_frames(state, rig, tables);
  if (k == 0) without[dataset] = a;
  const auto base = without.find(dataset);
  if (k != 0 && base != without.end()) {
    state.counters["k_over_0"] = a.ratio_ms() / base->second.ratio_ms();
  }
  state.SetLabel(std::string(kNames[dataset]) + "/skip_min_samples " + std::to_string(k));
}

BENCHMARK(BM_Table1)
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (int dataset = 0; dataset < 5; ++dataset) {
        const std::vector<int> counts =
            dataset == 4 ? std::vector<int>{1, 4, 16} : std::vector<int>{1, 4};
        for (int channels : counts) {
          for (RenderMode m : {RenderMode::pagetable, RenderMode::octree, RenderMode::residency}) {
            b->Args({dataset, channels, int(m)});
          }
        }
      }
    })
    ->ArgNames({"dataset", "channels", "mode"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_SkipMinSamples)
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (int dataset = 0; dataset < 5; ++dataset) {
        for (int k : {0, int(kDefaultSkipMinSamples)}) b->Args({dataset, k});
      }
    })
    ->ArgNames({"dataset", "k"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return resoct::bench::run_benchmarks(argc, argv);
}
