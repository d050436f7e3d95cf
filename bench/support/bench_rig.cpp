#include "support/bench_rig.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>

#include "resoct/frame_tables.hpp"

namespace resoct::bench {

namespace {
Preset g_preset = Preset::standard;

bool env_set(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}
}  // namespace

Preset init_preset(int& argc, char** argv) {
  if (env_set("RESOCT_BENCH_LARGE")) g_preset = Preset::large;
  if (env_set("RESOCT_BENCH_SMOKE")) g_preset = Preset::smoke;
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--large") == 0) {
      g_preset = Preset::large;
    } else if (std::strcmp(argv[i], "--smoke") == 0) {
      g_preset = Preset::smoke;
    } else {
      argv[out++] = argv[i];
    }
  }
  argc = out;
  benchmark::AddCustomContext("resoct_preset", to_string(g_preset));
  return g_preset;
}

Preset preset() {
  return g_preset;
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
         glm::uvec3 leaf_size) {
  BrickLayout layout;
  layout.brick_size = brick_size;
  source = std::make_unique<ProceduralSource>(spec, layout);
  test::ResidentOptions options;
  options.leaf_size = leaf_size;
  resident = std::make_unique<test::ResidentScene>(*source, std::move(channels), options);
  resident->upload(backend);
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
    c.tf = bench_tf(s, visible);
    sc.channels.push_back(c);
  }
  return sc;
}

std::uint32_t orbit_frames() {
  return g_preset == Preset::smoke ? 2u : g_preset == Preset::large ? 16u : 4u;
}

std::vector<FrameTables> orbit_tables(const Rig& rig, const Scene& scene, RenderMode mode,
                                      std::uint32_t frames) {
  std::vector<FrameTables> out;
  FrameOptions o;
  o.mode = mode;
  for (std::uint32_t f = 0; f < frames; ++f) {
    Scene s = scene;
    s.camera = orbit_camera(rig.source->hierarchy().volume(),
                            2.0 * std::numbers::pi * double(f) / double(frames));
    o.frame_index = f;
    out.push_back(rig.resident->tables(s, o));
  }
  return out;
}

FrameAverages run_frames(benchmark::State& state, Rig& rig,
                         const std::vector<FrameTables>& tables) {
  FrameResult result;
  BackendStats total;
  double slots = 0;
  std::int64_t frames = 0;
  for (auto _ : state) {
    for (const FrameTables& t : tables) {
      rig.backend.render(t, result);
      benchmark::DoNotOptimize(result.image.pixels().data());
      benchmark::ClobberMemory();
      total.rays += result.stats.rays;
      total.samples += result.stats.samples;
      total.nodes_visited += result.stats.nodes_visited;
      total.brick_accesses += result.stats.brick_accesses;
      total.ms_render += result.stats.ms_render;
      slots += double(result.used_cache_slots.size());
      ++frames;
    }
  }
  FrameAverages a;
  const double f = double(frames);
  const double rays = double(total.rays);
  a.ms_frame = total.ms_render / f;
  a.bricks_touched = slots / f;
  a.working_set_bytes = a.bricks_touched * double(rig.brick_bytes);
  a.samples_per_ray = double(total.samples) / rays;
  a.nodes_per_ray = double(total.nodes_visited) / rays;
  a.brick_accesses_per_ray = double(total.brick_accesses) / rays;
  state.counters["ms_frame"] = a.ms_frame;
  state.counters["working_set_MiB"] = a.working_set_bytes / double(1 << 20);
  state.counters["samples_per_ray"] = a.samples_per_ray;
  state.counters["nodes_per_ray"] = a.nodes_per_ray;
  state.counters["bricks_touched"] = a.bricks_touched;
  state.counters["brick_accesses_per_ray"] = a.brick_accesses_per_ray;
  state.SetItemsProcessed(std::int64_t(total.rays));
  return a;
}

int run_benchmarks(int argc, char** argv) {
  init_preset(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace resoct::bench
