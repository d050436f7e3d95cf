// Decoupling of brick size and octree leaf size (paper 000 Fig. 10): the thin multi-channel
// slab (procedural cells) with 32³ bricks, octree leaves of 32³, 16³, 8³ and 8×8×4, and 1..16
// visible channels; ms/frame of each render mode. CPU backend, one thread, every level of all
// 16 channels resident, camera rotating about the up axis (one iteration = one orbit, as
// bench_table1); timed: Backend::render alone.
//
//   BM_Decoupling/leaf:<l>/channels:<c>/mode:<m>
//     l = 0 32³, 1 16³, 2 8³, 3 8×8×4;  c = visible channels;  m = 1 pagetable, 2 octree,
//     0 residency (residency rows also report res_over_pt and res_over_oct)
// Counters as bench_table1. Sizes: 512×512×40 with 128² images (standard), 1024×1024×40 with
// 512² (--large or RESOCT_BENCH_LARGE=1), 64×64×40 with 32² (--smoke or RESOCT_BENCH_SMOKE=1).
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "support/bench_rig.hpp"

namespace {

using namespace resoct;
using namespace resoct::bench;

const glm::uvec3 kLeaves[] = {glm::uvec3(32), glm::uvec3(16), glm::uvec3(8), glm::uvec3(8, 8, 4)};
const char* const kLeafNames[] = {"32^3", "16^3", "8^3", "8x8x4"};

Rig& rig_for(int leaf) {
  static int key = -1;
  static std::unique_ptr<Rig> rig;
  if (!rig || key != leaf) {
    rig.reset();
    const Preset p = preset();
    const std::string spec = std::string("procedural:cells:") +
                             (p == Preset::smoke   ? "64x64x40"
                              : p == Preset::large ? "1024x1024x40"
                                                   : "512x512x40") +
                             ":16";
    std::vector<std::uint32_t> channels;
    for (std::uint32_t c = 0; c < 16; ++c) channels.push_back(c);
    rig = std::make_unique<Rig>(spec, channels, glm::uvec3(32), kLeaves[leaf]);
    key = leaf;
  }
  return *rig;
}

void BM_Decoupling(benchmark::State& state) {
  static std::map<std::tuple<int, int, int>, double> ms;
  const int leaf = int(state.range(0));
  const int channels = int(state.range(1));
  const auto mode = RenderMode(std::uint32_t(state.range(2)));
  Rig& rig = rig_for(leaf);
  const std::uint32_t image = preset() == Preset::smoke   ? 32u
                              : preset() == Preset::large ? 512u
                                                          : 128u;
  const Scene scene = bench_scene(rig, std::uint32_t(channels), image);
  const auto tables = orbit_tables(rig, scene, mode, orbit_frames());
  const FrameAverages a = run_frames(state, rig, tables);
  ms[{leaf, channels, int(mode)}] = a.ratio_ms();
  if (mode == RenderMode::residency) {
    const auto pt = ms.find({leaf, channels, int(RenderMode::pagetable)});
    const auto oct = ms.find({leaf, channels, int(RenderMode::octree)});
    if (pt != ms.end()) state.counters["res_over_pt"] = a.ratio_ms() / pt->second;
    if (oct != ms.end()) state.counters["res_over_oct"] = a.ratio_ms() / oct->second;
  }
  state.SetLabel(std::string("leaf ") + kLeafNames[leaf] + "/" + to_string(mode));
}

BENCHMARK(BM_Decoupling)
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (int leaf = 0; leaf < 4; ++leaf) {
        for (int channels : {1, 2, 4, 8, 16}) {
          for (RenderMode m : {RenderMode::pagetable, RenderMode::octree, RenderMode::residency}) {
            b->Args({leaf, channels, int(m)});
          }
        }
      }
    })
    ->ArgNames({"leaf", "channels", "mode"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return resoct::bench::run_benchmarks(argc, argv);
}
