// The limit (issue 13): resoct's CPU backend against the ideal dense in-core march
// (support/dense_march.hpp) on the same scene, in one process, with the same thread count.
//
// The dense march holds one channel's level-0 voxels in one flat array and marches every ray with
// the kernel's definition (camera rays, step, midpoint samples, trilinear clamp-to-edge, 1024-entry
// LUT, opacity correction, front-to-back compositing, early termination) but without bricks,
// octree, page table, empty-space skipping or level of detail. The backend renders with every
// brick of every level resident (bench_rig's Rig, the tests' ResidentScene). Both sample level 0
// only: the scenes' channels use levels [0, 0], so the images must agree (the counters report the
// largest and mean difference).
//
//   BM_Limit/scene:<s>/impl:<i>
//     s = 0 sphere: procedural:sphere 256³ (f32), camera and TF of examples/scenes/sphere.json,
//         512² (ERT 0.99)
//         1 sphere, no culling inside it: the same volume and camera, a TF visible at every value
//         above 0 with opacity 0.004..0.012 per voxel, ert_opacity 1.0 (no ray terminates early).
//         Value 0 stays transparent: resoct treats all-zero bricks as EMPTY, transparent whatever
//         the TF says about 0 (docs/rendering.md, "Deviations"), so a TF visible at 0 would
//         render the sphere's zero corners in the dense march only; the backend may still skip
//         them, the dense march cannot
//         2 nothing to skip: procedural:ramp 256³ (f32, no zero and no constant brick), the TF of
//         scene 1 made visible at 0 too, ERT 1.0, the sphere's camera: every segment of every
//         ray is sampled by both
//         3..7 the Table 1 datasets of bench_table1, one channel: tubes, noisefloor, turbulence,
//         mandelbulb (256³ u8) and cells channel 0 (512×512×40 u16), bench_tf, orbit camera at
//         angle 0, 256²
//     i = 0 dense march, 3 oracle culling (the dense march's visible samples alone, recorded in an
//         untimed pass: the per-ray set-up and the samples that add colour, nothing spent on
//         finding them; its image must equal the dense image bit for bit), 1 backend residency
//         mode, 2 backend page-table mode (run in this order per scene, so the backend rows
//         report their ratios against the dense and oracle rows)
// One benchmark iteration = one frame. Threads: 2 (RESOCT_LIMIT_THREADS=N to change), for both.
// Counters (per frame): ms_frame (wall), cpu_ms_frame (CPU time of the whole process: all render
// threads), samples (dense: segments evaluated; backend: samples that produced a value — skipped
// segments are not samples), samples_per_ray, ns_sample_core (CPU ns per sample: per core),
// ns_sample_wall_core (wall ns × threads per sample); dense rows: visible_per_ray (samples with TF
// alpha > 0); backend rows: iterations_per_ray (segments including skipped ones), nodes_per_ray,
// over_dense_wall / over_dense_cpu (backend ms / dense ms, wall and CPU), over_oracle_cpu (backend
// CPU ms / oracle CPU ms; oracle rows: over_dense_cpu as well), dense_samples_ratio
// (backend samples / dense samples), max_diff_255 / mean_diff_255 (largest and mean absolute RGB
// difference of the backend image from the dense image, in 1/255 units; the mean is over all
// pixels and colour components; a row whose difference exceeds 4/255 is reported as an error).
// RESOCT_LIMIT_OUT=DIR additionally writes each scene's images (DIR/limit_<scene>_<impl>.png) and
// the sphere's level-0 voxels (DIR/sphere_<W>x<H>x<D>_f32.raw, x fastest) for bench/peers.
// Sizes: standard as above; --smoke / RESOCT_BENCH_SMOKE=1: sphere 32³ at 32², Table 1 datasets
// 48³ / 64×64×40 at 32²; --large: sphere 512³ at 1024², Table 1 datasets 1024³ / 1024×1024×40
// at 512².
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/render/frame_tables.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/scene/scene.hpp"
#include "support/bench_rig.hpp"
#include "support/dense_march.hpp"

#ifndef RESOCT_SOURCE_DIR
#define RESOCT_SOURCE_DIR "."
#endif

namespace {

using namespace resoct;
using namespace resoct::bench;

constexpr const char* kSceneNames[] = {"sphere",     "sphere_noskip", "ramp_noskip", "tubes",
                                       "noisefloor", "turbulence",    "mandelbulb",  "cells"};
constexpr const char* kImplNames[] = {"dense", "residency", "pagetable", "oracle"};
constexpr int kOracle = 3;
constexpr int kScenes = 8;
constexpr int kFirstTable1 = 3;
// Largest image difference accepted (1/255 units). Float rounding alone stays below 0.01; a ray
// whose opacity lands within rounding of ert_opacity may stop one sample earlier in one renderer,
// which changes the pixel by at most (1 − ert_opacity) · colour (0.97/255 measured at 0.99).
constexpr double kMaxDiff255 = 4.0;

int thread_count() {
  const char* v = std::getenv("RESOCT_LIMIT_THREADS");
  const long n = v != nullptr ? std::strtol(v, nullptr, 10) : 0;
  return n >= 1 && n <= 1024 ? int(n) : 2;
}

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

double wall_ms() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string spec_for(int scene) {
  const Preset p = preset();
  if (scene < kFirstTable1) {
    return std::string(scene == 2 ? "procedural:ramp:" : "procedural:sphere:") +
           (p == Preset::smoke   ? "32x32x32"
            : p == Preset::large ? "512x512x512"
                                 : "256x256x256");
  }
  if (scene == 7) {
    return std::string("procedural:cells:") +
           (p == Preset::smoke   ? "64x64x40"
            : p == Preset::large ? "1024x1024x40"
                                 : "512x512x40") +
           ":16";
  }
  const char* size = p == Preset::smoke   ? "48x48x48"
                     : p == Preset::large ? "1024x1024x1024"
                                          : "256x256x256";
  return std::string("procedural:") + kSceneNames[scene] + ":" + size + ":1";
}

std::uint32_t image_size(int scene) {
  const Preset p = preset();
  if (p == Preset::smoke) return 32u;
  if (scene < kFirstTable1) return p == Preset::large ? 1024u : 512u;
  return p == Preset::large ? 512u : 256u;
}

// Scene s over `rig` (channel 0 in slot 0), levels [0, 0].
Scene make_scene(int s, const Rig& rig) {
  Scene sc;
  if (s < kFirstTable1) {
    sc = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
    if (s >= 1) {
      // Low opacity everywhere (0 excepted for the sphere, see the header), no termination.
      const double a0 = s == 1 ? 0.0 : 0.004;
      sc.channels[0].tf = TransferFunction({{0.0, {0.2, 0.4, 1.0, a0}},
                                            {0.001, {0.2, 0.4, 1.0, 0.004}},
                                            {0.5, {0.9, 0.8, 0.2, 0.008}},
                                            {1.0, {1.0, 1.0, 1.0, 0.012}}});
      sc.ert_opacity = 1.0;
    }
  } else {
    sc = bench_scene(rig, 1, 1);
  }
  const std::uint32_t n = image_size(s);
  sc.viewport = {n, n};
  sc.channels.resize(1);
  sc.channels[0].channel = 0;
  sc.channels[0].finest_level = 0;
  sc.channels[0].coarsest_level = 0;
  return sc;
}

struct ImplResult {
  double wall_ms = 0, cpu_ms = 0, samples = 0;
};

// One scene at a time: its rig (everything resident), dense volume and march, frame tables and
// the images compared before timing.
struct Case {
  int scene = -1;
  std::unique_ptr<Rig> rig;
  std::unique_ptr<DenseVolume> volume;
  std::unique_ptr<DenseMarch> dense;
  Scene sc;
  FrameTables tables[3];
  Image dense_image;
  VisibleSamples visible;  // the oracle's samples: the dense march's visible ones
  double max_diff[4] = {0, 0, 0, 0}, mean_diff[4] = {0, 0, 0, 0};
  std::map<int, ImplResult> done;
};

void image_diff(const Image& a, const Image& b, double& max_abs, double& mean_abs) {
  max_abs = 0;
  double sum = 0;
  const auto& pa = a.pixels();
  const auto& pb = b.pixels();
  for (std::size_t i = 0; i < pa.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double d = std::abs(double(pa[i][c]) - double(pb[i][c]));
      max_abs = std::max(max_abs, d);
      sum += d;
    }
  }
  mean_abs = pa.empty() ? 0.0 : sum / double(3 * pa.size());
}

Case& case_for(int scene) {
  static Case c;
  static std::string spec_loaded;
  if (c.scene == scene) return c;
  const int threads = thread_count();
  const std::string spec = spec_for(scene);
  if (spec != spec_loaded) {  // scenes 0 and 1 share the sphere
    c = Case{};
    spec_loaded.clear();
    c.rig = std::make_unique<Rig>(spec, std::vector<std::uint32_t>{0}, glm::uvec3(32),
                                  glm::uvec3(16), 0u, threads);
    c.volume = std::make_unique<DenseVolume>(DenseVolume::read(*c.rig->procedural, 0));
    spec_loaded = spec;
  }
  c.scene = -1;
  c.done.clear();
  c.sc = make_scene(scene, *c.rig);
  c.dense = std::make_unique<DenseMarch>(*c.volume, c.sc);
  FrameOptions o;
  o.mode = RenderMode::residency;
  c.tables[1] = c.rig->resident->tables(c.sc, o);
  o.mode = RenderMode::pagetable;
  c.tables[2] = c.rig->resident->tables(c.sc, o);
  c.dense->render(c.dense_image, threads);
  c.visible = c.dense->record_visible(threads);
  {
    Image oracle;
    c.dense->render_visible(oracle, c.visible, threads);
    image_diff(oracle, c.dense_image, c.max_diff[kOracle], c.mean_diff[kOracle]);
  }
  const char* out = std::getenv("RESOCT_LIMIT_OUT");
  const std::string dir = out != nullptr ? out : "";
  const auto png = [&](int impl, const Image& img) {
    if (!dir.empty()) {
      write_png(img, dir + "/limit_" + kSceneNames[scene] + "_" + kImplNames[impl] + ".png");
    }
  };
  png(0, c.dense_image);
  for (int impl = 1; impl <= 2; ++impl) {
    FrameResult r;
    c.rig->backend->render(c.tables[impl], r);
    image_diff(r.image, c.dense_image, c.max_diff[impl], c.mean_diff[impl]);
    png(impl, r.image);
  }
  if (!dir.empty() && scene == 0) {
    const glm::u64vec3 e = c.volume->volume.extent;
    const std::string path = dir + "/sphere_" + std::to_string(e.x) + "x" + std::to_string(e.y) +
                             "x" + std::to_string(e.z) + "_f32.raw";
    const std::vector<std::byte> core = c.volume->core();
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(core.data()), std::streamsize(core.size()));
    if (!f) throw Error(ErrorCode::io, path + ": cannot write");
  }
  c.scene = scene;
  return c;
}

void BM_Limit(benchmark::State& state) {
  const int scene = int(state.range(0));
  const int impl = int(state.range(1));
  const int threads = thread_count();
  Case* cp = nullptr;
  try {
    cp = &case_for(scene);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  Case& c = *cp;
  double wall = 0, cpu = 0, samples = 0, visible = 0, iterations = 0, nodes = 0, rays = 0;
  std::int64_t frames = 0;
  Image image;
  FrameResult result;
  // One untimed frame (faults in the image and, for the backend, its request buffers).
  if (impl == 0) {
    c.dense->render(image, threads);
  } else if (impl == kOracle) {
    c.dense->render_visible(image, c.visible, threads);
  } else {
    c.rig->backend->render(c.tables[impl], result);
  }
  for (auto _ : state) {
    const double w0 = wall_ms(), c0 = process_cpu_ms();
    if (impl == 0 || impl == kOracle) {
      const DenseStats st = impl == 0 ? c.dense->render(image, threads)
                                      : c.dense->render_visible(image, c.visible, threads);
      const double c1 = process_cpu_ms(), w1 = wall_ms();
      wall += w1 - w0;
      cpu += c1 - c0;
      samples += double(st.samples);
      visible += double(st.visible_samples);
      iterations += double(st.samples);
      rays += double(st.rays);
      benchmark::DoNotOptimize(image.pixels().data());
    } else {
      c.rig->backend->render(c.tables[impl], result);
      const double c1 = process_cpu_ms(), w1 = wall_ms();
      wall += w1 - w0;
      cpu += c1 - c0;
      samples += double(result.stats.samples);
      iterations += double(result.stats.iterations);
      nodes += double(result.stats.nodes_visited);
      rays += double(result.stats.rays);
      benchmark::DoNotOptimize(result.image.pixels().data());
    }
    benchmark::ClobberMemory();
    ++frames;
  }
  const double f = double(frames);
  ImplResult r{wall / f, cpu / f, samples / f};
  c.done[impl] = r;
  state.counters["threads"] = threads;
  state.counters["ms_frame"] = r.wall_ms;
  state.counters["cpu_ms_frame"] = r.cpu_ms;
  state.counters["samples"] = r.samples;
  state.counters["samples_per_ray"] = samples / rays;
  state.counters["ns_sample_core"] = r.samples > 0 ? r.cpu_ms * 1e6 / r.samples : 0.0;
  state.counters["ns_sample_wall_core"] =
      r.samples > 0 ? r.wall_ms * 1e6 * double(threads) / r.samples : 0.0;
  if (impl == 0) {
    state.counters["visible_per_ray"] = visible / rays;
  } else if (impl == kOracle) {
    // Bit for bit: the oracle composites exactly the dense march's visible samples.
    if (c.max_diff[kOracle] != 0.0) {
      state.SkipWithError(("the oracle's image differs from the dense march's by " +
                           std::to_string(c.max_diff[kOracle] * 255.0) + "/255")
                              .c_str());
    }
    if (const auto d = c.done.find(0); d != c.done.end()) {
      state.counters["over_dense_wall"] = r.wall_ms / d->second.wall_ms;
      state.counters["over_dense_cpu"] = r.cpu_ms / d->second.cpu_ms;
    }
  } else {
    state.counters["iterations_per_ray"] = iterations / rays;
    state.counters["nodes_per_ray"] = nodes / rays;
    state.counters["max_diff_255"] = c.max_diff[impl] * 255.0;
    state.counters["mean_diff_255"] = c.mean_diff[impl] * 255.0;
    if (c.max_diff[impl] * 255.0 > kMaxDiff255) {
      state.SkipWithError(("the backend's image differs from the dense march's by " +
                           std::to_string(c.max_diff[impl] * 255.0) + "/255")
                              .c_str());
    }
    if (const auto d = c.done.find(0); d != c.done.end()) {
      state.counters["over_dense_wall"] = r.wall_ms / d->second.wall_ms;
      state.counters["over_dense_cpu"] = r.cpu_ms / d->second.cpu_ms;
      state.counters["dense_samples_ratio"] = r.samples / d->second.samples;
    }
    if (const auto o = c.done.find(kOracle); o != c.done.end()) {
      state.counters["over_oracle_cpu"] = r.cpu_ms / o->second.cpu_ms;
    }
  }
  state.SetItemsProcessed(std::int64_t(rays));
  state.SetLabel(std::string(kSceneNames[scene]) + "/" + kImplNames[impl]);
}

BENCHMARK(BM_Limit)
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (int s = 0; s < kScenes; ++s) {
        for (const int impl : {0, kOracle, 1, 2}) b->Args({s, impl});
      }
    })
    ->ArgNames({"scene", "impl"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return resoct::bench::run_benchmarks(argc, argv);
}
