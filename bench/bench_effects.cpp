// What each effect costs (docs/architecture.md §4, issue "Effects on demand"): per dataset, every
// effect alone and combined against the plain path in one process, CPU backend, one thread, every
// level resident, the orbit of bench_table1. Each benchmark renders one configuration over the
// orbit; the plain configuration runs first per dataset and the others report their ratio to it.
//
//   BM_Effects/dataset:<d>/config:<c>
//     d = 0 tubes (1 channel), 1 turbulence (1 channel), 2 cells (4 of 16 channels)
//     c = 0 plain (the scene declares no effect: the mask-0 kernel)
//         1 plain again (a second, independent measurement: the noise of a ratio)
//         2 shading, central differences
//         3 shading, forward differences (paper 004 §7.1: central costs 15-30 % more)
//         4 / 5 / 6 shading + shadows, shadow LOD factor 1 / 2 / 4 (paper 004 §7.2)
//         7 isosurface (channel 0 at 0.35; other channels DVR)
//         8 isosurface + shadows (factor 2)
//         9 MIP (every channel), 10 AIP (every channel)
//         11 combined: channel 0 iso, shading and shadows (factor 2) on the rest, and on
//            cells channel 2 as MIP
//         12 pre-integrated transfer functions alone (kernel/preintegration.glsl.h)
//         13 shading with pre-integration
// Counters: ms_frame, cpu_ms_frame, ratio (FrameAverages::ratio_ms over plain's: the render
// thread's CPU time, which other processes on the machine do not inflate), wall_ratio (ms_frame
// over plain's, for comparison), gradient_evals_per_ray, shadow_rays_per_ray,
// and image errors: rmse_vs_central (forward vs central differences), shadow_rmse (shadows at
// factor 2 / 4 against factor 1, RGB RMSE over the image).
//
// "Effect code compiled in costs nothing when unused": the plain configurations run the mask-0
// instantiation, whose effect branches are discarded at compile time (if constexpr), so it is
// the pre-effects kernel; config 1 / config 0 shows the measurement noise of such a ratio, and
// bench/README.md compares plain ms/frame of bench_traverse before and after the effects.
// Sizes: as bench_accuracy (128³ / 256×256×40, 128² images; --smoke 24³ / 64×64×40, 24²).
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "support/bench_rig.hpp"

namespace {

using namespace resoct;
using namespace resoct::bench;

constexpr const auto& kNames = kEffectDatasetNames;
constexpr const char* kConfigs[] = {"plain",
                                    "plain (repeat)",
                                    "shading central",
                                    "shading forward",
                                    "shadows x1",
                                    "shadows x2",
                                    "shadows x4",
                                    "iso",
                                    "iso+shadows x2",
                                    "mip",
                                    "aip",
                                    "combined",
                                    "preintegration",
                                    "shading central + preintegration"};
constexpr int kConfigCount = 14;

Rig& rig_for(int dataset) {
  static int key = -1;
  static std::unique_ptr<Rig> rig;
  if (!rig || key != dataset) {
    rig.reset();
    std::vector<std::uint32_t> channels;
    for (std::uint32_t c = 0; c < effect_dataset_visible_channels(dataset); ++c)
      channels.push_back(c);
    rig = std::make_unique<Rig>(effect_dataset_spec(dataset), channels, glm::uvec3(32),
                                glm::uvec3(16));
    key = dataset;
  }
  return *rig;
}

Scene config_scene(const Rig& rig, int dataset, int config) {
  Scene s = bench_scene(rig, effect_dataset_visible_channels(dataset), effect_dataset_image_size());
  s.light.kind = Light::Kind::directional;
  s.light.vector = {-0.6, -1.0, -0.3};
  auto shadows = [&](std::uint32_t factor) {
    s.effects = {Effect::shading, Effect::shadows};
    s.shadow_lod_factor = factor;
  };
  switch (config) {
    case 2: s.effects = {Effect::shading}; break;
    case 3:
      s.effects = {Effect::shading};
      s.gradient = GradientStencil::forward;
      break;
    case 4: shadows(1); break;
    case 5: shadows(2); break;
    case 6: shadows(4); break;
    case 7:
    case 8:
      s.channels[0].mode = ChannelMode::iso;
      s.channels[0].isovalues = {0.35};
      if (config == 8) s.effects = {Effect::shadows};
      break;
    case 9:
    case 10:
      for (auto& c : s.channels) c.mode = config == 9 ? ChannelMode::mip : ChannelMode::aip;
      break;
    case 11:
      s.channels[0].mode = ChannelMode::iso;
      s.channels[0].isovalues = {0.35};
      if (s.channels.size() > 2) s.channels[2].mode = ChannelMode::mip;
      shadows(2);
      break;
    case 12: s.preintegration = true; break;
    case 13:
      s.effects = {Effect::shading};
      s.preintegration = true;
      break;
    default: break;
  }
  return s;
}

// Per dataset: plain's frame averages, and the first-frame images the error counters compare
// against.
std::map<int, FrameAverages> g_plain;
std::map<std::pair<int, int>, Image> g_images;

void BM_Effects(benchmark::State& state) {
  const int dataset = int(state.range(0));
  const int config = int(state.range(1));
  Rig& rig = rig_for(dataset);
  const Scene scene = config_scene(rig, dataset, config);
  const std::vector<FrameTables> tables =
      orbit_tables(rig, scene, RenderMode::residency, orbit_frames());
  FrameResult first;
  rig.backend->render(tables[0], first);
  const double rays = double(first.stats.rays);
  g_images[{dataset, config}] = first.image;
  const FrameAverages a = run_frames(state, rig, tables);
  if (config == 0) g_plain[dataset] = a;
  const auto plain = g_plain.find(dataset);
  if (plain != g_plain.end()) {
    state.counters["ratio"] = a.ratio_ms() / plain->second.ratio_ms();
    state.counters["wall_ratio"] = a.ms_frame / plain->second.ms_frame;
  }
  state.counters["gradient_evals_per_ray"] = double(first.stats.gradient_evals) / rays;
  state.counters["shadow_rays_per_ray"] = double(first.stats.shadow_rays) / rays;
  auto error_vs = [&](int other, const char* name) {
    const auto it = g_images.find({dataset, other});
    if (it != g_images.end())
      state.counters[name] = compare_images(first.image, it->second).rmse_rgb;
  };
  if (config == 3) error_vs(2, "rmse_vs_central");
  if (config == 5 || config == 6) error_vs(4, "shadow_rmse");
  state.SetLabel(std::string(kNames[dataset]) + "/" + kConfigs[config]);
}

BENCHMARK(BM_Effects)
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (int dataset = 0; dataset < 3; ++dataset) {
        for (int c = 0; c < kConfigCount; ++c) b->Args({dataset, c});
      }
    })
    ->ArgNames({"dataset", "config"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return resoct::bench::run_benchmarks(argc, argv);
}
