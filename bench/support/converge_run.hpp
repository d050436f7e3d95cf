#pragma once
// Cold-cache runs of the whole frame loop (Renderer) for the out-of-core and scaling benchmarks:
// a fresh Renderer per run, frames until converged or a frame cap, with the host-side totals that
// the per-frame reports and the loader keep.
#include <cstdint>
#include <memory>
#include <string>

#include "resoct/sources/brick_source.hpp"
#include "resoct/render/frame_stats.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct::bench {

/// Totals of one cold-cache run.
struct ConvergeRun {
  std::uint32_t frames = 0;  ///< frames rendered (the converged one included)
  bool converged = false;
  double ms_total = 0;              ///< wall time of all frames (loads included when synchronous)
  double ms_last_frame = 0;         ///< wall time of the last render_frame
  double ms_steady = 0;             ///< mean render_frame after convergence (0 if not measured)
  std::uint64_t bricks_loaded = 0;  ///< bricks read from the source
  std::uint64_t host_hits = 0;      ///< bricks served again by the host cache
  std::uint64_t bricks_uploaded = 0;
  std::uint64_t bytes_uploaded = 0;
  std::uint64_t evictions = 0;
  std::uint64_t working_set_bricks = 0;  ///< distinct cache slots sampled by the last frame
  std::uint64_t working_set_bytes = 0;
  std::uint64_t brick_bytes = 0;  ///< padded bytes of one brick
  std::uint32_t cache_slots = 0;
  std::uint32_t page_blocks = 0;       ///< page-table pool blocks allocated after the run
  std::uint32_t page_pool_blocks = 0;  ///< pool capacity (device blocks, block 0 included)
  std::uint64_t page_table_bytes = 0;  ///< host directory + allocated pool blocks
  FrameStats last;                     ///< statistics of the last frame
  Image image;                         ///< the last frame
};

/// A scene over dataset channels 0..visible-1 with the rig's transfer functions (duplicate_tf
/// when `duplicated`, else bench_tf), camera at orbit angle `angle`.
Scene source_scene(const VolumeDesc& volume, std::uint32_t visible, std::uint32_t image,
                   bool duplicated, double angle = 0.0);

/// Renders `scene` with a fresh Renderer until a frame converges or `max_frames` were rendered,
/// then `steady_frames` more (timed into ms_steady) when it converged.
ConvergeRun converge(std::shared_ptr<const BrickSource> source, const Scene& scene,
                     const RendererOptions& options, std::uint32_t max_frames,
                     std::uint32_t steady_frames = 0);

}  // namespace resoct::bench
