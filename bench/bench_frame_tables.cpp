// What the per-frame tables cost on the host when a viewer changes one thing between frames
// (issue 15: "changing only the transfer function or the camera rebuilds only what depends on
// it"). build_frame_tables() into one reused FrameTables, as Renderer does every frame, over a
// 16-channel procedural volume, 4 channels shown, at 512²:
//
//   BM_FrameTables/preint:P/change:C   P = 0 plain, 1 with pre-integration tables;
//                                      C = 0 the camera orbits a step per frame (transfer
//                                          functions unchanged), 1 one channel's transfer
//                                          function alternates between two (camera still),
//                                          2 nothing changes.
//
// Time is per build; counter luts_built: transfer-function LUTs computed per build (of 4).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <memory>

#include "support/bench_rig.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/render/frame_tables.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct::bench {
namespace {

constexpr std::uint32_t kChannels = 4;

struct TablesRig {
  std::shared_ptr<const BrickSource> source =
      make_procedural_source("procedural:cells:128x128x64:16", BrickLayout{glm::uvec3(32), 1});
  OctreeLayout layout{source->hierarchy().volume().extent, glm::uvec3(16)};
  PageTable pages{source->hierarchy(), kChannels, 16};
  ChannelMap channels{kChannels, source->hierarchy().volume().channels};
  Scene scene;
  TablesRig() {
    for (std::uint32_t c = 0; c < kChannels; ++c) channels.assign(c, c, pages);
    scene.viewport = Viewport{512, 512};
    scene.camera = orbit_camera(source->hierarchy().volume(), 0.0);
    for (std::uint32_t c = 0; c < kChannels; ++c) {
      ChannelSettings s;
      s.channel = c;
      s.tf = bench_tf(c, kChannels);
      scene.channels.push_back(s);
    }
  }
};

void BM_FrameTables(benchmark::State& state) {
  const bool preint = state.range(0) != 0;
  const int change = int(state.range(1));
  TablesRig rig;
  rig.scene.preintegration = preint;
  const TransferFunction tf_a = rig.scene.channels[1].tf;
  const TransferFunction tf_b = duplicate_tf(1, 2);
  FrameOptions o;
  FrameTables tables;
  build_frame_tables(rig.scene, rig.source->hierarchy(), rig.layout, rig.channels, o, tables);
  std::uint64_t frame = 0;
  std::uint64_t luts = 0;
  for (auto _ : state) {
    ++frame;
    if (change == 0) {
      rig.scene.camera = orbit_camera(rig.source->hierarchy().volume(), 0.01 * double(frame));
    } else if (change == 1) {
      rig.scene.channels[1].tf = frame % 2 == 0 ? tf_a : tf_b;
    }
    o.frame_index = std::uint32_t(frame);
    build_frame_tables(rig.scene, rig.source->hierarchy(), rig.layout, rig.channels, o, tables);
    luts += tables.luts_built;
    benchmark::DoNotOptimize(tables.tf_luts.data());
    benchmark::ClobberMemory();
  }
  const double n = double(state.iterations());
  state.counters["luts_built"] = double(luts) / n;
}

BENCHMARK(BM_FrameTables)
    ->ArgNames({"preint", "change"})
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace resoct::bench

BENCHMARK_MAIN();
