#include "support/bench_rig.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <numbers>
#include <string_view>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/base/error.hpp"
#include "resoct/render/frame_tables.hpp"
#include "support/duplicate_source.hpp"
#ifdef RESOCT_BENCH_HAVE_VULKAN
#include "resoct/vulkan/vulkan_backend.hpp"
#endif

namespace resoct::bench {

namespace {
Preset g_preset = Preset::standard;
std::string g_backend = "cpu";

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

bool env_set(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}
}  // namespace

Preset init_preset(int& argc, char** argv) {
  cpu::register_backend();
#ifdef RESOCT_BENCH_HAVE_VULKAN
  vk::register_backend();
#endif
  if (env_set("RESOCT_BENCH_LARGE")) g_preset = Preset::large;
  if (env_set("RESOCT_BENCH_SMOKE")) g_preset = Preset::smoke;
  if (const char* b = std::getenv("RESOCT_BENCH_BACKEND"); b != nullptr && *b != '\0') {
    g_backend = b;
  }
  constexpr std::string_view kBackendFlag = "--backend=";
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--large") {
      g_preset = Preset::large;
    } else if (arg == "--smoke") {
      g_preset = Preset::smoke;
    } else if (arg.starts_with(kBackendFlag)) {
      g_backend = std::string(arg.substr(kBackendFlag.size()));
    } else {
      argv[out++] = argv[i];
    }
  }
  argc = out;
  const std::vector<std::string> names = backend_names();
  if (std::find(names.begin(), names.end(), g_backend) == names.end()) {
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw invalid_parameter("backend", "'" + g_backend + "' is not built in (have: " + known + ")");
  }
  benchmark::AddCustomContext("resoct_preset", to_string(g_preset));
  benchmark::AddCustomContext("resoct_backend", g_backend);
  return g_preset;
}

const std::string& backend_name() {
  return g_backend;
}

std::unique_ptr<Backend> make_backend(int threads) {
  BackendOptions o;
  o.threads = threads;
  return create_backend(g_backend, o);
}

Preset preset() {
  return g_preset;
}

std::string effect_dataset_spec(int dataset) {
  const Preset p = preset();
  if (dataset == 2) {
    return std::string("procedural:cells:") +
           (p == Preset::smoke   ? "64x64x40"
            : p == Preset::large ? "512x512x40"
                                 : "256x256x40") +
           ":16";
  }
  const char* size = p == Preset::smoke   ? "24x24x24"
                     : p == Preset::large ? "256x256x256"
                                          : "128x128x128";
  return std::string("procedural:") + kEffectDatasetNames[dataset] + ":" + size + ":1";
}

std::uint32_t effect_dataset_visible_channels(int dataset) {
  return dataset == 2 ? 4u : 1u;
}

std::uint32_t effect_dataset_image_size() {
  return preset() == Preset::smoke ? 24u : preset() == Preset::large ? 256u : 128u;
}

const char* to_string(Preset p) {
  switch (p) {
    case Preset::smoke: return "smoke";
    case Preset::large: return "large";
    case Preset::standard: break;
  }
  return "standard";
}

Rig::Rig(const std::string& spec, std::vector<std::uint32_t> channels, glm::uvec3 brick_size,
         glm::uvec3 leaf_size, std::uint32_t duplicates, int threads, bool brick_errors) {
  BrickLayout layout;
  layout.brick_size = brick_size;
  procedural = std::make_shared<ProceduralSource>(spec, layout);
  source = procedural;
  if (duplicates > 0) {
    source = std::make_shared<DuplicateChannelSource>(procedural, 0, duplicates);
    duplicated = true;
  }
  test::ResidentOptions options;
  options.leaf_size = leaf_size;
  options.brick_errors = brick_errors;
  resident = std::make_unique<test::ResidentScene>(*source, std::move(channels), options);
  backend = make_backend(threads);
  resident->upload(*backend);
  const BrickHierarchy& h = source->hierarchy();
  brick_bytes = std::size_t(h.layout().padded_voxels() * voxel_size(h.volume().type));
}

Camera orbit_camera(const VolumeDesc& volume, double angle) {
  const glm::dvec3 centre = 0.5 * box_extent(volume);
  Camera c;
  c.target = centre;
  c.eye = centre + glm::dvec3(1.6 * std::sin(angle), 0.35, 1.6 * std::cos(angle));
  c.fov_deg = 40.0;
  return c;
}

TransferFunction bench_tf(std::uint32_t k, std::uint32_t n) {
  const double hue = double(k) / double(n);
  return TransferFunction({{0.0, {1, 1, 1, 0}},
                           {0.1, {1, 1, 1, 0}},
                           {0.4, {hue, 1.0 - hue, 0.5, 0.05}},
                           {1.0, {1.0, hue, 1.0 - hue, 0.3}}});
}

TransferFunction duplicate_tf(std::uint32_t k, std::uint32_t n) {
  const double hue = double(k) / double(n);
  const double lo = 0.1 + 0.5 * double(k) / double(n);
  return TransferFunction({{0.0, {1, 1, 1, 0}},
                           {lo, {1, 1, 1, 0}},
                           {lo + 0.3 * (1.0 - lo), {hue, 1.0 - hue, 0.5, 0.05}},
                           {1.0, {1.0, hue, 1.0 - hue, 0.3}}});
}

Scene bench_scene(const Rig& rig, std::uint32_t visible, std::uint32_t image, std::uint32_t finest,
                  std::uint32_t coarsest) {
  Scene sc;
  sc.camera = orbit_camera(rig.source->hierarchy().volume(), 0.0);
  sc.viewport = {image, image};
  for (std::uint32_t s = 0; s < visible; ++s) {
    ChannelSettings c;
    c.channel = *rig.resident->channel_map().channel(s);
    c.finest_level = finest;
    c.coarsest_level = coarsest;
    c.tf = rig.duplicated ? duplicate_tf(s, visible) : bench_tf(s, visible);
    sc.channels.push_back(c);
  }
  return sc;
}

std::uint32_t orbit_frames() {
  return g_preset == Preset::smoke ? 2u : g_preset == Preset::large ? 16u : 4u;
}

std::vector<FrameTables> orbit_tables(const Rig& rig, const Scene& scene, RenderMode mode,
                                      std::uint32_t frames, float skip_min_samples) {
  std::vector<FrameTables> out;
  FrameOptions o;
  o.mode = mode;
  for (std::uint32_t f = 0; f < frames; ++f) {
    Scene s = scene;
    s.camera = orbit_camera(rig.source->hierarchy().volume(),
                            2.0 * std::numbers::pi * double(f) / double(frames));
    o.frame_index = f;
    out.push_back(rig.resident->tables(s, o, skip_min_samples));
  }
  return out;
}

double FrameAverages::ratio_ms() const {
  return backend_name() == "cpu" && cpu_ms_frame > 0 ? cpu_ms_frame : ms_frame;
}

FrameAverages run_frames(benchmark::State& state, Rig& rig,
                         const std::vector<FrameTables>& tables) {
  FrameResult result;
  // One untimed frame first: the Vulkan backend creates pipelines and buffers lazily, and the
  // first CPU frame faults in the image and request buffers.
  if (!tables.empty()) rig.backend->render(tables.front(), result);
  BackendStats total;
  double slots = 0;
  double cpu_ms = 0;
  std::int64_t frames = 0;
  for (auto _ : state) {
    for (const FrameTables& t : tables) {
      const double cpu0 = thread_cpu_ms();
      rig.backend->render(t, result);
      cpu_ms += thread_cpu_ms() - cpu0;
      benchmark::DoNotOptimize(result.image.pixels().data());
      benchmark::ClobberMemory();
      total.rays += result.stats.rays;
      total.samples += result.stats.samples;
      total.nodes_visited += result.stats.nodes_visited;
      total.brick_accesses += result.stats.brick_accesses;
      total.ms_render += result.stats.ms_render;
      total.ms_device += result.stats.ms_device;
      slots += double(result.used_cache_slots.size());
      ++frames;
    }
  }
  FrameAverages a;
  const double f = double(frames);
  const double rays = double(total.rays);
  a.ms_frame = total.ms_render / f;
  a.ms_device = total.ms_device / f;
  a.cpu_ms_frame = cpu_ms / f;
  a.bricks_touched = slots / f;
  a.working_set_bytes = a.bricks_touched * double(rig.brick_bytes);
  a.samples_per_ray = double(total.samples) / rays;
  a.nodes_per_ray = double(total.nodes_visited) / rays;
  a.brick_accesses_per_ray = double(total.brick_accesses) / rays;
  state.counters["ms_frame"] = a.ms_frame;
  if (a.ms_device > 0) state.counters["ms_device"] = a.ms_device;
  state.counters["cpu_ms_frame"] = a.cpu_ms_frame;
  state.counters["working_set_MiB"] = a.working_set_bytes / double(1 << 20);
  state.counters["samples_per_ray"] = a.samples_per_ray;
  state.counters["nodes_per_ray"] = a.nodes_per_ray;
  state.counters["bricks_touched"] = a.bricks_touched;
  state.counters["brick_accesses_per_ray"] = a.brick_accesses_per_ray;
  state.SetItemsProcessed(std::int64_t(total.rays));
  return a;
}

int run_benchmarks(int argc, char** argv) {
  try {
    init_preset(argc, argv);
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace resoct::bench
