#pragma once
/// \file
/// The frame loop: a Renderer owns the host-side residency state (page table, brick cache,
/// residency octree, channel map), a BrickLoader and a Backend, and turns a Scene into images
/// frame by frame (docs/architecture.md §2). See docs/renderer.md.
///
/// This header is what a viewer needs: it names none of the engine's structures, which live
/// behind a private implementation. Tests, tools and benchmarks that look at them include
/// resoct/render/renderer_inspection.hpp (resoct::inspect).

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "resoct/backend/backend.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/engine/load_failure.hpp"
#include "resoct/render/frame_jitter.hpp"
#include "resoct/render/frame_stats.hpp"
#include "resoct/render/renderer_options.hpp"
#include "resoct/scene/scene.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/volume/hierarchy.hpp"

namespace resoct {

/// One rendered frame. A viewer keeps one and passes it to every render_frame(scene, report):
/// the renderer then reuses its pixel buffers instead of allocating an image per frame.
struct FrameReport {
  std::uint32_t width = 0;  ///< the frame's size, whichever output it carries
  std::uint32_t height = 0;
  /// Float RGBA, straight alpha (ViewerOptions::output rgba32f or both, or device on the CPU
  /// backend; else empty).
  Image image;
  /// 8-bit RGBA, 4 bytes per pixel, row 0 at the top, as Image::to_rgba8 (output rgba8 or both;
  /// else empty).
  std::vector<std::uint8_t> rgba8;
  /// With output device on a device backend: the frame's float image in device memory, valid
  /// until the next frame (DeviceImage in backend.hpp says how to read it); handle 0 otherwise.
  DeviceImage device_image;
  /// True when the frame needed nothing it did not have: no brick or node requests other than
  /// for bricks that failed to load, no dropped requests, nothing queued, loading or waiting.
  bool converged = false;
  FrameStats stats;
  std::vector<LoadFailure> failures;  ///< bricks that failed to load, each reported once
};

struct ConvergeReport {
  FrameReport last;  ///< the last frame; its `failures` lists those of all frames rendered
  std::uint32_t frames = 0;
  bool converged = false;
};

namespace inspect {
struct Access;  // renderer_inspection.hpp
}  // namespace inspect

/// Thread-safety: none; drive one Renderer from one thread. The loader threads it owns read the
/// source concurrently (BrickSource members are thread-safe).
class Renderer {
 public:
  /// Renders with `backend` (resoct::cpu::make_backend(), resoct::vk::make_backend(), or an
  /// application's own Backend); RendererOptions::backend and ::backend_options are ignored.
  /// Validates the options, builds the host structures and configures the backend. Throws
  /// Error(invalid_argument) naming "backend" when it is null, Error(unsupported) naming
  /// "backend" when it was compiled against another kernel record layout
  /// (Backend::kernel_layout_version()), Error naming "source" when the source is null, or as
  /// the structures' constructors do. A ViewerOptions converts to RendererOptions.
  Renderer(std::shared_ptr<const BrickSource> source, std::unique_ptr<Backend> backend,
           RendererOptions options = {});
  /// Name-based creation, for the command-line tools: validates the options, then creates the
  /// backend registered as RendererOptions::backend (Error(invalid_argument) naming "backend"
  /// when it is unknown) and continues as the constructor above.
  Renderer(std::shared_ptr<const BrickSource> source, RendererOptions options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// One frame: maps the scene's channels to slots, applies loaded bricks within the upload
  /// budget, sends deltas, renders, and hands the frame's requests to the loader. A scene of
  /// another timepoint than the last frame's (an absent Scene::timepoint meaning the source's
  /// own) first switches (docs/renderer.md "Time series"):
  /// every brick and node summary of the old timepoint is invalidated, so the frame shows only
  /// the new timepoint, coarse levels first. Throws Error(invalid_argument) naming "scene" when
  /// it is invalid for the volume (its `timepoint` past the source's) or has more channels than
  /// visible slots.
  FrameReport render_frame(const Scene& scene);
  /// The same into `report`, whose pixel buffers are reused: after the first two frames of a size
  /// no frame allocates image memory. Every field of `report` is overwritten. Unchanged when the
  /// scene is rejected.
  void render_frame(const Scene& scene, FrameReport& report);
  /// The same with every ray moved by `jitter` (sub-pixel offset, sample shift), for averaging
  /// frames of an unchanged view (FrameAccumulator, docs/rendering.md "Jittered accumulation").
  /// A zero jitter renders exactly the frame above. Throws Error(invalid_argument) naming
  /// "jitter.*" when it is out of range (FrameJitter::validate); `report` is then unchanged.
  void render_frame(const Scene& scene, FrameReport& report, const FrameJitter& jitter);
  /// Renders until a frame reports converged or `max_frames` frames were rendered (>= 1).
  ConvergeReport render_until_converged(const Scene& scene, std::uint32_t max_frames = 1000);

  /// The timepoint the last frame showed (the source's own before the first frame).
  std::uint32_t timepoint() const noexcept;
  /// Timepoints of the source (BrickSource::timepoints()).
  std::uint32_t timepoints() const noexcept;

  /// Blocks until the loader has nothing queued or in flight (returns at once with 0 threads).
  void wait_for_loads();

  /// Called once per failed brick as soon as the failure is known (also listed in the report).
  void set_failure_callback(std::function<void(const LoadFailure&)> fn);

  const RendererOptions& options() const noexcept;
  const BrickSource& source() const noexcept;
  const BrickHierarchy& hierarchy() const noexcept;
  std::uint64_t frame_index() const noexcept;

 private:
  // The engine's structures and the frame loop (renderer.cpp); renderer_inspection.hpp reads
  // them through inspect::Access.
  friend struct inspect::Access;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace resoct
