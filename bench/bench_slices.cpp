// Cost of slices and the lens against the plain path, and paging with a lens.
//
//   BM_SliceLensFrame/variant:V   CPU backend, one thread, everything resident (tubes, 1 channel),
//     orbit of orbit_frames() cameras; counters ms_frame (per frame), ratio_vs_plain (ms_frame /
//     variant 0's, when variant 0 ran first in this process), samples_per_ray.
//       V = 0 plain; 1 one slice that no ray meets (the per-ray hook alone); 2 one oblique slice
//       over the volume; 3 three axis-aligned slices over the volume; 4 three slices, volume
//       transparent (slices only); 5 lens (size 0.3) hiding the outside; 6 lens (0.3) with the
//       outside at levels [2, 15].
//   BM_LensPaging/lens_permille:S  a cold Renderer (synchronous loads) converges on tubes with a
//     lens of edge S/1000 box units hiding the outside (S = 1000: no lens); counters
//     bricks_paged (page entries resident at convergence: mapped, empty or homogeneous), frames,
//     ms_converge (wall time of render_until_converged).
// Presets: smoke (ctest) tubes 64³, 32² image; standard tubes 256³ (frames) / 512³ (paging),
// 128² image; large 1024³ / 256².
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "support/bench_rig.hpp"

namespace {

using namespace resoct;
using namespace resoct::bench;

std::uint32_t frame_extent() {
  return preset() == Preset::smoke ? 64u : (preset() == Preset::large ? 1024u : 256u);
}
std::uint32_t paging_extent() {
  return preset() == Preset::smoke ? 64u : (preset() == Preset::large ? 1024u : 512u);
}
std::uint32_t image_size() {
  return preset() == Preset::smoke ? 32u : (preset() == Preset::large ? 256u : 128u);
}

std::string tubes(std::uint32_t e) {
  const std::string n = std::to_string(e);
  return "procedural:tubes:" + n + "x" + n + "x" + n;
}

SlicePlane plane(glm::dvec3 point, glm::dvec3 normal, double level) {
  SlicePlane p;
  p.point = point;
  p.normal = normal;
  p.channels = {0};
  p.window = 1.0;
  p.level = level;
  return p;
}

Lens lens_of(double size, bool coarse_outside) {
  Lens l;
  l.center = glm::dvec3(0.5);
  l.size = glm::dvec3(size);
  if (coarse_outside) {
    LensOutside o;
    o.channel = 0;
    o.hide = false;
    o.finest_level = 2;
    o.coarsest_level = 15;
    l.outside = {o};
  }
  return l;
}

Scene variant_scene(const Rig& rig, int v) {
  Scene s = bench_scene(rig, 1, image_size());
  const std::vector<SlicePlane> axis3 = {plane({0.5, 0.5, 0.5}, {1, 0, 0}, 0.5),
                                         plane({0.5, 0.45, 0.5}, {0, 1, 0}, 0.5),
                                         plane({0.5, 0.5, 0.55}, {0, 0, 1}, 0.5)};
  switch (v) {
    case 1: s.slices = {plane({0.5, 0.5, -40.0}, {0, 0, 1}, 0.5)}; break;
    case 2: s.slices = {plane({0.5, 0.5, 0.5}, {0.3, 0.8, 0.5}, 0.5)}; break;
    case 3: s.slices = axis3; break;
    case 4:
      s.slices = axis3;
      s.channels[0].tf = TransferFunction({{0.0, {0, 0, 0, 0}}, {1.0, {0, 0, 0, 0}}});
      break;
    case 5: s.lens = lens_of(0.3, false); break;
    case 6: s.lens = lens_of(0.3, true); break;
    default: break;
  }
  return s;
}

double g_plain_ms = 0.0;

void BM_SliceLensFrame(benchmark::State& state) {
  static std::unique_ptr<Rig> rig;
  if (!rig)
    rig = std::make_unique<Rig>(tubes(frame_extent()), std::vector<std::uint32_t>{0},
                                glm::uvec3(32), glm::uvec3(16));
  const int v = int(state.range(0));
  const Scene scene = variant_scene(*rig, v);
  const std::vector<FrameTables> tables =
      orbit_tables(*rig, scene, RenderMode::residency, orbit_frames());
  const FrameAverages a = run_frames(state, *rig, tables);
  if (v == 0) g_plain_ms = a.ms_frame;
  if (g_plain_ms > 0.0) state.counters["ratio_vs_plain"] = a.ms_frame / g_plain_ms;
}
BENCHMARK(BM_SliceLensFrame)
    ->ArgName("variant")
    ->DenseRange(0, 6)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_LensPaging(benchmark::State& state) {
  const std::shared_ptr<const BrickSource> source =
      make_procedural_source(tubes(paging_extent()), BrickLayout{});
  const double size = double(state.range(0)) / 1000.0;
  std::uint64_t paged = 0;
  std::uint32_t frames = 0;
  double ms = 0.0;
  for (auto _ : state) {
    RendererOptions o;
    o.backend = backend_name();
    o.backend_options.threads = 1;
    o.loader_threads = 0;
    o.strategy = RequestStrategy::global;
    o.device_cache_bytes = std::uint64_t(64) << 20;
    o.host_cache_bytes = std::uint64_t(256) << 20;
    Renderer renderer(source, o);
    Scene s;
    s.camera = orbit_camera(source->hierarchy().volume(), 0.3);
    s.viewport = {image_size(), image_size()};
    ChannelSettings c;
    c.tf = bench_tf(0, 1);
    s.channels = {c};
    if (state.range(0) < 1000) s.lens = lens_of(size, false);
    const auto t0 = std::chrono::steady_clock::now();
    const ConvergeReport rep = renderer.render_until_converged(s, 200);
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(rep.last.image.pixels().data());
    frames = rep.frames;
    paged = 0;
    for (std::uint32_t e : inspect::page_table(renderer).pool()) {
      if (kernel::resoct_page_state(e) != kernel::RESOCT_PAGE_STATE_UNMAPPED) ++paged;
    }
  }
  state.counters["bricks_paged"] = double(paged);
  state.counters["frames"] = double(frames);
  state.counters["ms_converge"] = ms;
}
BENCHMARK(BM_LensPaging)
    ->ArgName("lens_permille")
    ->Arg(50)
    ->Arg(100)
    ->Arg(200)
    ->Arg(400)
    ->Arg(1000)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return run_benchmarks(argc, argv);
}
