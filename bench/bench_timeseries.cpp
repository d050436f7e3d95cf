// Frames to converge after a timepoint switch while playing a time series, with and without
// prefetching of the next timepoint (PrefetchOptions::next_timepoint; docs/renderer.md "Time
// series"). A still camera shows each timepoint for `hold` frames after it converged, then the
// scene switches to the next one; frames are paced at a fixed period (a display loop that does
// not wait for loads) and every brick read costs a fixed latency (a slow disk or a server), so
// loading, not rendering, limits how fast a new timepoint converges. Every timepoint holds the
// same voxels (turbulence): bricks are keyed by timepoint, so each switch must load them anew,
// which is what is measured. Counters (means over the switches):
//   frames_to_converge  frames from the switching frame (included) to the first converged one
//   ms_render_to_converge  render_frame time of those frames (they are `period` apart)
//   loads_per_switch    bricks read from the source after the switch
//   prefetch_hits       requests served by bricks read ahead (whole run)
// Arg: next (0 = prefetching of the next timepoint off, 1 = on). One iteration per run.
// RESOCT_BENCH_SMOKE=1: a tiny volume, two timepoints, no latency.
// RESOCT_TIMESERIES_PERIOD_MS (default 250), RESOCT_TIMESERIES_LATENCY_US (default 8000),
// RESOCT_TIMESERIES_HOLD (frames shown per timepoint, default 6).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "support/loading_bench.hpp"
#include "resoct/scene/scene.hpp"

using namespace resoct;

namespace {

long env_or(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v ? std::atol(v) : fallback;
}

/// `timepoints` timepoints of one procedural volume, each read with a fixed latency.
class SlowSeries final : public BrickSource {
 public:
  SlowSeries(std::shared_ptr<const BrickSource> inner, std::uint32_t timepoints, std::uint32_t t,
             std::chrono::microseconds latency)
      : inner_(std::move(inner)), timepoints_(timepoints), t_(t), latency_(latency) {}
  const BrickHierarchy& hierarchy() const override { return inner_->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    std::this_thread::sleep_for(latency_);
    inner_->read_brick(key, out);
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_->region_meta(c, b);
  }
  std::string name() const override { return "slow-series:" + inner_->name(); }
  std::uint32_t timepoints() const override { return timepoints_; }
  std::uint32_t timepoint() const override { return t_; }
  std::shared_ptr<const BrickSource> open_timepoint(std::uint32_t t) const override {
    return std::make_shared<SlowSeries>(inner_, timepoints_, t, latency_);
  }

 private:
  std::shared_ptr<const BrickSource> inner_;
  std::uint32_t timepoints_ = 1;
  std::uint32_t t_ = 0;
  std::chrono::microseconds latency_;
};

void BM_TimepointSwitch(benchmark::State& state) {
  const bool next = state.range(0) != 0;
  const bool tiny = bench::loading_smoke();
  const std::uint32_t timepoints = tiny ? 2 : 5;
  const auto period =
      std::chrono::milliseconds(tiny ? 1 : env_or("RESOCT_TIMESERIES_PERIOD_MS", 250));
  const auto latency =
      std::chrono::microseconds(tiny ? 0 : env_or("RESOCT_TIMESERIES_LATENCY_US", 8000));
  const auto hold = std::uint32_t(tiny ? 1 : env_or("RESOCT_TIMESERIES_HOLD", 6));
  constexpr std::uint32_t kMaxFrames = 400;  // per switch: a cap, not reached in practice
  cpu::register_backend();
  Scene scene = parse_scene(bench::kTurbulenceScene, "turbulence");
  scene.viewport = Viewport{tiny ? 24u : 32u, tiny ? 24u : 32u};
  scene.camera.eye = scene.camera.target + 0.75 * (scene.camera.eye - scene.camera.target);

  double frames = 0, ms = 0, loads = 0, hits = 0, switches = 0, converged = 0;
  for (auto _ : state) {
    const std::shared_ptr<const BrickSource> volume = make_procedural_source(
        tiny ? "procedural:turbulence:48x48x48" : "procedural:turbulence:192x192x192",
        BrickLayout{glm::uvec3(16), 1});
    RendererOptions o;
    o.backend = "cpu";
    o.backend_options.threads = 1;
    o.loader_threads = 1;
    o.leaf_size = glm::uvec3(16);
    o.prefetch.next_timepoint = next;
    o.prefetch.max_bricks = 48;
    Renderer r(std::make_shared<SlowSeries>(volume, timepoints, 0, latency), o);
    // A frame paced at `period`: the display loop does not wait for loads.
    const auto paced_frame = [&] {
      const auto t0 = std::chrono::steady_clock::now();
      FrameReport rep = r.render_frame(scene);
      std::this_thread::sleep_until(t0 + period);
      return rep;
    };
    const auto show = [&] {
      for (std::uint32_t i = 0; i < hold; ++i) paced_frame();
    };
    // Timepoint 0 converges first (not measured): the series starts from a complete image.
    scene.timepoint = 0;
    r.render_until_converged(scene, kMaxFrames);
    show();
    for (std::uint32_t t = 1; t < timepoints; ++t) {
      scene.timepoint = t;
      const std::uint64_t loads_before = inspect::loader(r).stats().loads;
      std::uint32_t f = 0;
      bool done = false;
      while (!done && f < kMaxFrames) {
        const FrameReport rep = paced_frame();
        ++f;
        ms += rep.stats.ms_frame;
        done = rep.converged;
      }
      switches += 1;
      converged += done ? 1 : 0;
      frames += double(f);
      loads += double(inspect::loader(r).stats().loads - loads_before);
      show();
    }
    hits += double(inspect::loader(r).stats().prefetch_hits);
  }
  const double n = std::max(1.0, switches);
  state.counters["frames_to_converge"] = frames / n;
  // Rendering alone (the rest of each frame's period was waiting for the display).
  state.counters["ms_render_to_converge"] = ms / n;
  state.counters["loads_per_switch"] = loads / n;
  state.counters["prefetch_hits"] = hits / double(state.iterations());
  state.counters["switches"] = switches / double(state.iterations());
  state.counters["converged_switches"] = converged / double(state.iterations());
  state.SetLabel(next ? "prefetch next timepoint" : "no prefetch");
}

}  // namespace

BENCHMARK(BM_TimepointSwitch)
    ->ArgNames({"next"})
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
