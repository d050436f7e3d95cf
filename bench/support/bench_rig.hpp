#pragma once
// Shared rig of the paper-comparison benchmarks (bench_table1, bench_decoupling, bench_accuracy,
// bench_out_of_core, bench_scaling): size presets, the backend under test (cpu or vulkan, chosen
// by RESOCT_BENCH_BACKEND or --backend=NAME), "everything resident" set-up of a procedural
// source (the tests' ResidentScene, so the benchmarks measure exactly what the tests verify), the
// rotating camera of paper 000 §8, and per-frame statistics with the working set.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "resoct/backend/backend.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/resident_scene.hpp"

namespace resoct::bench {

/// Problem sizes: smoke (ctest, seconds), standard (a few minutes on 2 cores), large (real
/// machines, 1024³ class).
enum class Preset { smoke, standard, large };

/// Reads RESOCT_BENCH_SMOKE / RESOCT_BENCH_LARGE / RESOCT_BENCH_BACKEND and removes --smoke /
/// --large / --backend=NAME from argv (before benchmark::Initialize sees them); registers the
/// backends this build has ("cpu", and "vulkan" when built with RESOCT_WITH_VULKAN). Throws
/// Error(invalid_argument) naming "backend" for an unknown backend. Call once from main.
Preset init_preset(int& argc, char** argv);
/// The main() of every rig benchmark: reads the preset and backend flags, then runs Google
/// Benchmark. Returns 1 (with one line on stderr) when a flag is bad.
int run_benchmarks(int argc, char** argv);
/// The preset chosen by init_preset.
Preset preset();
const char* to_string(Preset p);

/// The datasets of bench_accuracy and bench_effects, indexed 0..2: procedural tubes and
/// turbulence (one channel) and the cells slab (16 markers, the first 4 shown), sized by preset().
inline constexpr const char* kEffectDatasetNames[] = {"tubes", "turbulence", "cells"};
/// The source spec of effect dataset `dataset` at the current preset.
std::string effect_dataset_spec(int dataset);
/// Channels the benchmarks show of effect dataset `dataset`.
std::uint32_t effect_dataset_visible_channels(int dataset);
/// Square image edge of those benchmarks at the current preset.
std::uint32_t effect_dataset_image_size();

/// The backend under test ("cpu" unless RESOCT_BENCH_BACKEND or --backend says otherwise).
const std::string& backend_name();
/// A new backend under test; `threads` is honoured by the CPU backend (<= 0: all cores).
std::unique_ptr<Backend> make_backend(int threads);

/// A procedural source with every level of the given channels resident on the backend under
/// test (the CPU backend on one thread by default, so that ms/frame is the traversal's cost, not
/// the machine's parallelism). With `duplicates` > 0 the source shows channel 0 of `spec` as
/// that many identical channels (DuplicateChannelSource: the paper's multi-channel protocol for
/// single-channel data) and bench_scene gives each copy its own value window. With
/// `brick_errors` the coarse bricks carry their measured errors (error-bounded LOD).
struct Rig {
  Rig(const std::string& spec, std::vector<std::uint32_t> channels, glm::uvec3 brick_size,
      glm::uvec3 leaf_size, std::uint32_t duplicates = 0, int threads = 1,
      bool brick_errors = false);
  std::shared_ptr<ProceduralSource> procedural;  ///< the generated data
  std::shared_ptr<const BrickSource> source;     ///< what is rendered (procedural or duplicated)
  std::unique_ptr<test::ResidentScene> resident;
  std::unique_ptr<Backend> backend;
  std::size_t brick_bytes = 0;  ///< padded bytes of one cache slot
  bool duplicated = false;
};

/// Camera `angle` radians around the up (y) axis through the volume's centre, at distance 1.6
/// box units, slightly above (paper 000 §8: rotation about the up axis).
Camera orbit_camera(const VolumeDesc& volume, double angle);

/// A transfer function transparent below 0.1 (hides the noise floor), rising to a per-channel
/// hue; channel k of n.
TransferFunction bench_tf(std::uint32_t k, std::uint32_t n);
/// Transfer function of copy k of n of a duplicated channel (paper 000 §8: "rendering channels
/// with different transfer functions"): transparent below 0.1 + 0.5 k / n, so copy 0 is
/// bench_tf's window and later copies show progressively denser parts of the same data.
TransferFunction duplicate_tf(std::uint32_t k, std::uint32_t n);

/// A scene over the first `visible` slots of `rig` with bench_tf and the given level range.
Scene bench_scene(const Rig& rig, std::uint32_t visible, std::uint32_t image,
                  std::uint32_t finest = 0, std::uint32_t coarsest = 15);

/// Camera positions per orbit: 2 (smoke), 4 (standard), 16 (large).
std::uint32_t orbit_frames();

/// Frame tables of `frames` camera positions evenly spaced on the orbit; residency-mode tables
/// carry the visible-subtree bits of `skip_min_samples` (TuningOptions::skip_min_samples).
std::vector<FrameTables> orbit_tables(const Rig& rig, const Scene& scene, RenderMode mode,
                                      std::uint32_t frames,
                                      float skip_min_samples = kDefaultSkipMinSamples);

/// Per-frame averages of a run (benchmark time is per orbit; ms_frame is per frame).
struct FrameAverages {
  double ms_frame = 0, ms_device = 0, cpu_ms_frame = 0, working_set_bytes = 0, samples_per_ray = 0,
         nodes_per_ray = 0, bricks_touched = 0, brick_accesses_per_ray = 0;
  /// The time mode ratios are computed from: the calling thread's CPU time for the CPU backend
  /// (it renders on that thread when threads = 1, and CPU time does not count the time other
  /// processes hold the core, so ratios survive a loaded machine), wall time otherwise.
  double ratio_ms() const;
};

/// Renders all tables (one orbit) per benchmark iteration and returns per-frame averages; sets
/// the counters ms_frame (host wall time of Backend::render), cpu_ms_frame (CPU time of the
/// calling thread in Backend::render), ms_device (device timestamps; Vulkan only), working_set_MiB,
/// samples_per_ray, nodes_per_ray, bricks_touched.
FrameAverages run_frames(benchmark::State& state, Rig& rig, const std::vector<FrameTables>& tables);

}  // namespace resoct::bench
