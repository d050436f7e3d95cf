// Frames to convergence on a scripted camera path, with and without prefetching (paper 001's
// predictive paging by linear extrapolation). The camera orbits the volume (path 0, 5 degrees a
// frame) or flies towards its centre (path 1) for 24 frames and then stops; frames are paced at
// a fixed period (an interactive display loop that does not wait for loads), and every brick
// read costs a fixed latency (a slow disk or a remote server). Counters:
//   unconverged_on_path  frames along the path whose image still lacked bricks
//   frames_after_stop    frames after the camera stopped until the image converged
//   missing_requests     device brick requests summed over the path (how much was missing)
//   prefetched, prefetch_hits  bricks read ahead, and requests those reads served
// Args: lookahead frames (0 = prefetching off), path. One iteration per run (a cold renderer).
// RESOCT_BENCH_SMOKE=1: a short path, no latency.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "support/loading_bench.hpp"
#include "resoct/scene/scene.hpp"

using namespace resoct;

namespace {

/// Adds a fixed latency to every brick read.
class SlowSource final : public BrickSource {
 public:
  SlowSource(std::unique_ptr<BrickSource> inner, std::chrono::microseconds latency)
      : inner_(std::move(inner)), latency_(latency) {}
  const BrickHierarchy& hierarchy() const override { return inner_->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    std::this_thread::sleep_for(latency_);
    inner_->read_brick(key, out);
  }
  BrickMeta brick_meta(BrickKey key) const override { return inner_->brick_meta(key); }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_->region_meta(c, b);
  }
  std::string name() const override { return "slow:" + inner_->name(); }

 private:
  std::unique_ptr<BrickSource> inner_;
  std::chrono::microseconds latency_;
};

/// Pose of frame f (held at the last pose after the path): kind 0 orbits the volume centre by
/// 5 degrees a frame; kind 1 flies towards the centre, from 1.0 to 0.45 of the start distance,
/// so that ever finer levels come into view.
Camera pose(const Camera& start, int kind, std::uint32_t f, std::uint32_t path) {
  const double u = double(std::min(f, path - 1));
  if (kind == 0) return orbit(start, 5.0 * u);
  Camera c = start;
  const double s = 1.0 - 0.55 * u / double(path - 1);
  c.eye = start.target + s * (start.eye - start.target);
  return c;
}

void BM_PrefetchPath(benchmark::State& state) {
  const auto lookahead = std::uint32_t(state.range(0));
  const int kind = int(state.range(1));
  const bool tiny = bench::loading_smoke();
  // The period exceeds the render time of a 32x32 frame even on a loaded machine, so that loading,
  // not rendering, limits progress: one loader thread at 8 ms per brick
  // (RESOCT_PREFETCH_LATENCY_US) reads about 30 bricks a frame, a little more than the orbit needs
  // anew per frame, so prefetching has idle reads to use.
  const std::uint32_t path = tiny ? 4 : 24;
  const char* env_period = std::getenv("RESOCT_PREFETCH_PERIOD_MS");
  const auto period = std::chrono::milliseconds(tiny         ? 1
                                                : env_period ? std::atol(env_period)
                                                             : 250);
  const char* env_latency = std::getenv("RESOCT_PREFETCH_LATENCY_US");
  const auto latency = std::chrono::microseconds(tiny          ? 0
                                                 : env_latency ? std::atol(env_latency)
                                                               : 8000);
  cpu::register_backend();
  Scene scene = parse_scene(bench::kTurbulenceScene, "turbulence");
  scene.viewport = Viewport{tiny ? 24u : 32u, tiny ? 24u : 32u};
  scene.camera.eye = scene.camera.target + 0.75 * (scene.camera.eye - scene.camera.target);

  double unconverged = 0, after_stop = 0, missing = 0, prefetched = 0, hits = 0, converged = 0;
  double render_ms = 0, frames = 0;
  for (auto _ : state) {
    auto src = std::make_shared<SlowSource>(
        make_procedural_source(
            tiny ? "procedural:turbulence:48x48x48" : "procedural:turbulence:192x192x192",
            BrickLayout{glm::uvec3(16), 1}),
        latency);
    RendererOptions o;
    o.backend = "cpu";
    o.backend_options.threads = 1;
    o.loader_threads = 1;
    o.leaf_size = glm::uvec3(16);
    o.prefetch.lookahead_frames = lookahead;
    o.prefetch.max_bricks = 48;
    Renderer r(src, o);
    std::uint32_t f = 0;
    bool done = false;
    for (; f < path + 200 && !done; ++f) {
      const auto t0 = std::chrono::steady_clock::now();
      Scene s = scene;
      s.camera = pose(scene.camera, kind, f, path);
      const FrameReport rep = r.render_frame(s);
      render_ms += rep.stats.ms_frame;
      frames += 1;
      if (f < path) {
        unconverged += rep.converged ? 0 : 1;
        missing += double(rep.stats.brick_requests);
      } else if (rep.converged) {
        done = true;
      } else {
        after_stop += 1;
      }
      std::this_thread::sleep_until(t0 + period);
    }
    converged += done ? 1 : 0;
    prefetched += double(inspect::loader(r).stats().prefetched);
    hits += double(inspect::loader(r).stats().prefetch_hits);
  }
  const double n = double(state.iterations());
  state.counters["unconverged_on_path"] = unconverged / n;
  state.counters["frames_after_stop"] = after_stop / n;
  state.counters["missing_requests"] = missing / n;
  state.counters["prefetched"] = prefetched / n;
  state.counters["prefetch_hits"] = hits / n;
  state.counters["path_frames"] = path;
  state.counters["converged"] = converged / n;
  // Above the period, rendering rather than loading limited the run (a loaded machine).
  state.counters["ms_per_frame"] = render_ms / std::max(1.0, frames);
  state.SetLabel(std::string(kind == 0 ? "orbit" : "dolly") +
                 (lookahead == 0 ? ", no prefetch" : ", prefetch"));
}

}  // namespace

BENCHMARK(BM_PrefetchPath)
    ->ArgNames({"lookahead", "path"})
    ->ArgsProduct({{0, 2, 4}, {0, 1}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
