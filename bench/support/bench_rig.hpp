#pragma once
// Shared rig of the paper-comparison benchmarks (bench_table1, bench_decoupling, bench_accuracy):
// size presets, "everything resident" set-up of a procedural source on a CPU backend (the tests'
// ResidentScene, so the benchmarks measure exactly what the tests verify), the rotating camera
// of paper 000 §8, and per-frame statistics with the working set.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/procedural_source.hpp"
#include "support/resident_scene.hpp"

namespace resoct::bench {

/// Problem sizes: smoke (ctest, seconds), standard (a few minutes on 2 cores), large (real
/// machines, 1024³ class).
enum class Preset { smoke, standard, large };

/// Reads RESOCT_BENCH_SMOKE / RESOCT_BENCH_LARGE and removes --smoke / --large from argv (before
/// benchmark::Initialize sees them). Call once from main.
Preset init_preset(int& argc, char** argv);
/// The main() of every rig benchmark: reads the preset flags, then runs Google Benchmark.
int run_benchmarks(int argc, char** argv);
/// The preset chosen by init_preset.
Preset preset();
const char* to_string(Preset p);

/// A procedural source with every level of the given channels resident on a one-thread CPU
/// backend (one thread so that ms/frame is the traversal's cost, not the machine's parallelism).
struct Rig {
  Rig(const std::string& spec, std::vector<std::uint32_t> channels, glm::uvec3 brick_size,
      glm::uvec3 leaf_size);
  std::unique_ptr<ProceduralSource> source;
  std::unique_ptr<test::ResidentScene> resident;
  cpu::CpuBackend backend{1};
  std::size_t brick_bytes = 0;  ///< padded bytes of one cache slot
};

/// Camera `angle` radians around the up (y) axis through the volume's centre, at distance 1.6
/// box units, slightly above (paper 000 §8: rotation about the up axis).
Camera orbit_camera(const VolumeDesc& volume, double angle);

/// A transfer function transparent below 0.1 (hides the noise floor), rising to a per-channel
/// hue; channel k of n.
TransferFunction bench_tf(std::uint32_t k, std::uint32_t n);

/// A scene over the first `visible` slots of `rig` with bench_tf and the given level range.
Scene bench_scene(const Rig& rig, std::uint32_t visible, std::uint32_t image,
                  std::uint32_t finest = 0, std::uint32_t coarsest = 15);

/// Camera positions per orbit: 2 (smoke), 4 (standard), 16 (large).
std::uint32_t orbit_frames();

/// Frame tables of `frames` camera positions evenly spaced on the orbit.
std::vector<FrameTables> orbit_tables(const Rig& rig, const Scene& scene, RenderMode mode,
                                      std::uint32_t frames);

/// Per-frame averages of a run (benchmark time is per orbit; ms_frame is per frame).
struct FrameAverages {
  double ms_frame = 0, working_set_bytes = 0, samples_per_ray = 0, nodes_per_ray = 0,
         bricks_touched = 0, brick_accesses_per_ray = 0;
};

/// Renders all tables (one orbit) per benchmark iteration and returns per-frame averages; sets
/// the counters ms_frame, working_set_MiB, samples_per_ray, nodes_per_ray, bricks_touched.
FrameAverages run_frames(benchmark::State& state, Rig& rig, const std::vector<FrameTables>& tables);

}  // namespace resoct::bench
