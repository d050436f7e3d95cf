// Frames to convergence on a scripted camera path, with and without prefetching (paper 001's
// predictive paging by linear extrapolation). The camera orbits the volume (path 0, 5 degrees a
// frame) or flies towards its centre (path 1) for 24 frames and then stops.
//
// Time is simulated, so every run gives the same counters: loading is synchronous
// (loader_threads = 0) and a frame reads at most K bricks (upload_budget.max_bricks), the
// requested ones first and prefetches only when no request is left (docs/renderer.md, step 8),
// which is a loader that reads K bricks per display period and takes a prefetch only while idle.
// K = 31 stands for a 250 ms period at 8 ms per brick read (a slow disk or a remote server);
// RESOCT_PREFETCH_BRICKS_PER_FRAME overrides it. Counters:
//   unconverged_on_path  frames along the path whose image still lacked bricks
//   frames_after_stop    frames after the camera stopped until the image converged
//   missing_requests     device brick requests summed over the path (how much was missing)
//   prefetched, prefetch_hits  bricks read ahead, and requests those reads served
//   bricks_read          bricks read in all (requests and prefetches), whole run
// Args: lookahead frames (0 = prefetching off), path. One iteration per run (a cold renderer).
// RESOCT_BENCH_SMOKE=1: a short path on a small volume.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "support/loading_bench.hpp"
#include "resoct/scene/scene.hpp"

using namespace resoct;

namespace {

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
  const std::uint32_t path = tiny ? 4 : 24;
  const char* env_k = std::getenv("RESOCT_PREFETCH_BRICKS_PER_FRAME");
  const std::uint64_t per_frame = tiny ? 8 : env_k ? std::strtoull(env_k, nullptr, 10) : 31;
  cpu::register_backend();
  Scene scene = parse_scene(bench::kTurbulenceScene, "turbulence");
  scene.viewport = Viewport{tiny ? 24u : 32u, tiny ? 24u : 32u};
  scene.camera.eye = scene.camera.target + 0.75 * (scene.camera.eye - scene.camera.target);

  double unconverged = 0, after_stop = 0, missing = 0, prefetched = 0, hits = 0, converged = 0;
  double read = 0;
  for (auto _ : state) {
    std::shared_ptr<const BrickSource> src = make_procedural_source(
        tiny ? "procedural:turbulence:48x48x48" : "procedural:turbulence:192x192x192",
        BrickLayout{glm::uvec3(16), 1});
    RendererOptions o;
    o.backend = "cpu";
    o.backend_options.threads = 1;
    o.loader_threads = 0;
    o.upload_budget.max_bricks = std::max<std::uint64_t>(per_frame, 1);
    o.leaf_size = glm::uvec3(16);
    o.prefetch.lookahead_frames = lookahead;
    o.prefetch.max_bricks = 48;
    Renderer r(src, o);
    bool done = false;
    for (std::uint32_t f = 0; f < path + 200 && !done; ++f) {
      Scene s = scene;
      s.camera = pose(scene.camera, kind, f, path);
      const FrameReport rep = r.render_frame(s);
      if (f < path) {
        unconverged += rep.converged ? 0 : 1;
        missing += double(rep.stats.brick_requests);
      } else if (rep.converged) {
        done = true;
      } else {
        after_stop += 1;
      }
    }
    converged += done ? 1 : 0;
    const BrickLoaderStats ls = inspect::loader(r).stats();
    prefetched += double(ls.prefetched);
    hits += double(ls.prefetch_hits);
    read += double(ls.loads + ls.prefetched);
  }
  const double n = double(state.iterations());
  state.counters["unconverged_on_path"] = unconverged / n;
  state.counters["frames_after_stop"] = after_stop / n;
  state.counters["missing_requests"] = missing / n;
  state.counters["prefetched"] = prefetched / n;
  state.counters["prefetch_hits"] = hits / n;
  state.counters["path_frames"] = path;
  state.counters["converged"] = converged / n;
  state.counters["bricks_read"] = read / n;
  state.counters["bricks_per_frame"] = double(per_frame);
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
