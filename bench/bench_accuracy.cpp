// What accuracy costs in time: images of the CPU backend (residency mode, one thread, every
// level resident) against the dense double-precision reference renderer of the tests
// (tests/support/reference_renderer, level 0, steps of 1/8 reference step, no early
// termination, exact transfer functions), one fixed view per dataset. Each benchmark renders
// one configuration: the image error is measured on the first frame, the timing (Backend::render
// only) over the benchmark loop.
//
//   BM_Accuracy/dataset:<d>/sweep:<s>/value:<v>
//     d = 0 tubes (1 channel), 1 turbulence (1 channel), 2 cells (4 of 16 channels)
//     s = 0 grid: step scale {0.25, 0.5, 1, 2, 4} × LOD error {0.5, 1, 2, 4, 8} px ×
//         pre-integration {off, on}, no early termination (ERT opacity 1.0), v = 10i + 2j + p
//         1 level ranges: v = L in 0..2 forces every channel to levels >= L; v = 3 gives channel
//           k the range k % 3 .. 15 (per-channel ranges)
//         2 octree leaf size: v = 0 32³, 1 16³, 2 8³ (step 1, LOD 1 px)
//         3 opacity correction at coarse steps: step {1, 2, 4} (v / 2), on (v even) or off
//           (v odd), level 0 only. "Off" scales the frame's reference step by the step scale,
//           so transfer-function alpha is applied per step as is (a renderer that ignores
//           the step length); the reference is always corrected.
//         4 early termination opacity {0.99, 0.995, 0.999} × step scale {0.25 .. 4} ×
//           pre-integration {off, on} at LOD 0.5 px, v = 6i + 2e + p (ERT 1.0 rows: grid)
//         5 error-bounded LOD (Scene::lod_error_color, docs/rendering.md): step scale
//           {0.25 .. 4} × LOD {0.5, 4} px (which then sets only the step, through the LOD
//           floor) × colour error {0.0025, 0.005, 0.01, 0.02, 0.04, 0.08}, no early
//           termination, pre-integration off, v = 12i + 6j + e: the level comes from the bricks'
//           measured errors instead of the footprint. Counter lod_color.
// Every other sweep: pre-integration off, the scene's ERT 0.99. The finest setting, the base of
// the speed-ups report.py prints, is the grid row step 0.25, LOD 0.5 px, ERT 1.0, pre-integration
// off: the most accurate point-sampling configuration, like the reference without termination.
// Counters: ms_frame, rmse (RGB, over the image, values in [0, 1]), psnr_db, max_err (largest
// absolute RGB difference), step_scale, lod_px, preint (0/1), ert (termination opacity), plus the
// working set and per-ray counters of bench_table1. bench/scripts/report.py extracts the Pareto
// front (rmse vs ms) per dataset. Sizes: 128³ / 256×256×40 with 128² images (standard), 256³ /
// 512×512×40 with 256² images
// (--large or RESOCT_BENCH_LARGE=1), 24³ / 64×64×40 with 24² images (--smoke or
// RESOCT_BENCH_SMOKE=1).
#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "support/bench_rig.hpp"
#include "support/reference_renderer.hpp"

namespace {

using namespace resoct;
using namespace resoct::bench;

constexpr const auto& kNames = kEffectDatasetNames;
constexpr double kSteps[] = {0.25, 0.5, 1.0, 2.0, 4.0};
constexpr double kLods[] = {0.5, 1.0, 2.0, 4.0, 8.0};
const glm::uvec3 kLeaves[] = {glm::uvec3(32), glm::uvec3(16), glm::uvec3(8)};
constexpr double kErts[] = {0.99, 0.995, 0.999};
constexpr double kColors[] = {0.0025, 0.005, 0.01, 0.02, 0.04, 0.08};

// One rig at a time; `errors`: coarse bricks carry their measured errors (sweep 5).
Rig& rig_for(int dataset, int leaf, bool errors = false) {
  static std::tuple<int, int, bool> key{-1, -1, false};
  static std::unique_ptr<Rig> rig;
  if (!rig || key != std::tuple<int, int, bool>{dataset, leaf, errors}) {
    rig.reset();
    std::vector<std::uint32_t> channels;
    for (std::uint32_t c = 0; c < effect_dataset_visible_channels(dataset); ++c)
      channels.push_back(c);
    rig = std::make_unique<Rig>(effect_dataset_spec(dataset), channels, glm::uvec3(32),
                                kLeaves[leaf], 0, 1, errors);
    key = {dataset, leaf, errors};
  }
  return *rig;
}

// Level-0 voxels of the loaded channels as doubles (the reference renderer's input).
test::VoxelFunction level0_voxels(const ProceduralSource& src, std::uint32_t channels) {
  const VolumeDesc& v = src.hierarchy().volume();
  const Box3 all{glm::i64vec3(0), glm::i64vec3(v.extent)};
  const std::size_t n = std::size_t(v.voxel_count());
  std::vector<std::vector<double>> out;
  std::vector<std::byte> bytes(n * voxel_size(v.type));
  for (std::uint32_t c = 0; c < channels; ++c) {
    src.read_region(0, c, all, bytes);
    std::vector<double> d(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (v.type == VoxelType::u8) {
        d[i] = double(std::uint8_t(bytes[i]));
      } else {
        std::uint16_t x;
        std::memcpy(&x, bytes.data() + 2 * i, 2);
        d[i] = double(x);
      }
    }
    out.push_back(std::move(d));
  }
  // The reference reads dataset channels by index; unloaded channels are never visible.
  for (std::uint32_t c = channels; c < v.channels; ++c) out.emplace_back(n, 0.0);
  return test::dense_voxels(v.extent, std::move(out));
}

// The reference image of a dataset's fixed view (computed once per dataset).
const Image& reference_for(int dataset, const Scene& scene) {
  static std::map<int, Image> cache;
  const auto it = cache.find(dataset);
  if (it != cache.end()) return it->second;
  const Rig& rig = rig_for(dataset, 1);
  const VolumeDesc& v = rig.source->hierarchy().volume();
  test::ReferenceOptions o;
  o.step = preset() == Preset::smoke ? 0.25 : 0.125;
  o.early_termination = false;
  return cache[dataset] = test::render_reference(
             scene, v, level0_voxels(*rig.procedural, effect_dataset_visible_channels(dataset)), o);
}

void BM_Accuracy(benchmark::State& state) {
  const int dataset = int(state.range(0));
  const int sweep = int(state.range(1));
  const int value = int(state.range(2));
  const int leaf = sweep == 2 ? value : 1;
  Scene scene = bench_scene(rig_for(dataset, 1, sweep == 5),
                            effect_dataset_visible_channels(dataset), effect_dataset_image_size());
  const Image& reference = reference_for(dataset, scene);
  Rig& rig = rig_for(dataset, leaf, sweep == 5);
  bool uncorrected = false;
  std::string label = kNames[dataset];
  switch (sweep) {
    case 0:
      scene.step_scale = kSteps[value / 10];
      scene.lod_error_px = kLods[(value / 2) % 5];
      scene.preintegration = value % 2 == 1;
      scene.ert_opacity = 1.0;
      label += scene.preintegration ? "/grid preint" : "/grid";
      break;
    case 1:
      for (std::size_t k = 0; k < scene.channels.size(); ++k) {
        scene.channels[k].finest_level = value < 3 ? std::uint32_t(value) : std::uint32_t(k % 3);
      }
      label += value < 3 ? "/levels>=" + std::to_string(value) : std::string("/levels k%3");
      break;
    case 2: label += std::string("/leaf ") + std::to_string(kLeaves[value].x) + "^3"; break;
    case 3:
      scene.step_scale = kSteps[2 + value / 2];
      uncorrected = value % 2 == 1;
      for (auto& c : scene.channels) c.coarsest_level = 0;
      label += uncorrected ? "/opacity-correction off" : "/opacity-correction on";
      break;
    case 5:
      scene.step_scale = kSteps[value / 12];
      scene.lod_error_px = (value / 6) % 2 == 0 ? 0.5 : 4.0;
      scene.lod_error_color = kColors[value % 6];
      scene.ert_opacity = 1.0;
      label += "/error-bounded " + std::to_string(kColors[value % 6]).substr(0, 6);
      break;
    default:
      scene.step_scale = kSteps[value / 6];
      scene.lod_error_px = 0.5;
      scene.ert_opacity = kErts[(value / 2) % 3];
      scene.preintegration = value % 2 == 1;
      label += "/ert " + std::to_string(kErts[(value / 2) % 3]).substr(0, 5) +
               (scene.preintegration ? " preint" : "");
      break;
  }
  FrameOptions o;
  o.mode = RenderMode::residency;
  std::vector<FrameTables> tables{rig.resident->tables(scene, o)};
  if (uncorrected) tables[0].frame.ref_step *= float(scene.step_scale);
  FrameResult first;
  rig.backend->render(tables[0], first);
  const ImageDiff diff = compare_images(first.image, reference);
  run_frames(state, rig, tables);
  state.counters["rmse"] = diff.rmse_rgb;
  state.counters["psnr_db"] = std::min(diff.psnr_rgb, 200.0);
  state.counters["max_err"] = std::max({diff.max_abs[0], diff.max_abs[1], diff.max_abs[2]});
  state.counters["step_scale"] = scene.step_scale;
  state.counters["lod_px"] = scene.lod_error_px;
  state.counters["preint"] = scene.preintegration ? 1.0 : 0.0;
  state.counters["ert"] = scene.ert_opacity;
  state.counters["lod_color"] = scene.lod_error_color;
  state.SetLabel(label);
}

BENCHMARK(BM_Accuracy)
    ->Apply([](benchmark::internal::Benchmark* b) {
      const int counts[] = {50, 4, 3, 6, 30, 60};
      for (int dataset = 0; dataset < 3; ++dataset) {
        for (int sweep = 0; sweep < 6; ++sweep) {
          for (int v = 0; v < counts[sweep]; ++v) b->Args({dataset, sweep, v});
        }
      }
    })
    ->ArgNames({"dataset", "sweep", "value"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return resoct::bench::run_benchmarks(argc, argv);
}
