#pragma once
/// \file
/// The frame loop: owns the host-side residency state (page table, brick cache, residency
/// octree, channel map), a BrickLoader and a Backend, and turns a Scene into images frame by
/// frame (docs/architecture.md §2). See docs/renderer.md.

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/backend/backend.hpp"
#include "resoct/engine/brick_cache.hpp"
#include "resoct/engine/brick_loader.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/render/frame_stats.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/prefetch.hpp"
#include "resoct/render/renderer_options.hpp"
#include "resoct/engine/request_set.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/scene/scene.hpp"

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

/// A camera position read by loader threads (host cache Octreemizer distances).
struct SharedEye {
  std::mutex mutex;
  glm::dvec3 eye{0.0};
};

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
  /// Renders until a frame reports converged or `max_frames` frames were rendered (>= 1).
  ConvergeReport render_until_converged(const Scene& scene, std::uint32_t max_frames = 1000);

  /// The timepoint the last frame showed (the source's own before the first frame).
  std::uint32_t timepoint() const noexcept { return timepoint_; }
  /// Timepoints of the source (BrickSource::timepoints()).
  std::uint32_t timepoints() const noexcept { return source_->timepoints(); }

  /// Blocks until the loader has nothing queued or in flight (returns at once with 0 threads).
  void wait_for_loads() { loader_->wait_idle(); }

  /// Called once per failed brick as soon as the failure is known (also listed in the report).
  void set_failure_callback(std::function<void(const LoadFailure&)> fn) {
    on_failure_ = std::move(fn);
  }

  const RendererOptions& options() const noexcept { return options_; }
  const BrickSource& source() const noexcept { return *source_; }
  const BrickHierarchy& hierarchy() const noexcept { return hierarchy_; }
  const OctreeLayout& layout() const noexcept { return layout_; }
  const PageTable& page_table() const noexcept { return pages_; }
  const BrickCache& cache() const noexcept { return *cache_; }
  const ResidencyOctree& octree() const noexcept { return *octree_; }
  const ChannelMap& channel_map() const noexcept { return channels_; }
  const BrickLoader& loader() const noexcept { return *loader_; }
  Backend& backend() noexcept { return *backend_; }
  const BackendConfig& backend_config() const noexcept { return config_; }
  std::uint64_t frame_index() const noexcept { return frame_; }

 private:
  static std::unique_ptr<Backend> named_backend(const RendererOptions& options);
  const FrameTables& frame_tables(const Scene& scene);
  void take_pixels(FrameReport& report);
  void assign_channels(const Scene& scene);
  void switch_timepoint(std::uint32_t t);
  /// Bricks of the next timepoint the scene's view may need, for PrefetchOptions::next_timepoint.
  void prefetch_next_timepoint(const Scene& scene, std::size_t max,
                               std::vector<TimedBrickKey>& keys);
  void apply_loaded(FrameStats& stats);
  bool apply_one(const LoadedBrick& b, FrameStats& stats);
  void evict(BrickKey key);
  void send_update(FrameStats& stats);
  void answer_nodes(FrameStats& stats);
  bool handle_requests(const FrameResult& result, std::uint64_t epoch, FrameStats& stats);
  void prefetch(const Scene& scene, FrameStats& stats);
  void report_failures(FrameReport& report);

  std::shared_ptr<const BrickSource> source_;
  // The shown timepoint and its source (region metadata is per timepoint).
  std::uint32_t timepoint_ = 0;
  std::shared_ptr<const BrickSource> timepoint_source_;
  RendererOptions options_;
  BrickHierarchy hierarchy_;
  OctreeLayout layout_;
  PageTable pages_;
  ChannelMap channels_;
  std::unique_ptr<BrickCache> cache_;
  std::unique_ptr<ResidencyOctree> octree_;
  std::unique_ptr<BrickLoader> loader_;
  std::unique_ptr<Backend> backend_;
  BackendConfig config_;
  std::function<void(const LoadFailure&)> on_failure_;

  std::vector<std::uint32_t> channel_rank_;  // per dataset channel: load rank in this scene
  glm::dvec3 camera_{0.0};                   // eye in physical units (Octreemizer distances)
  // The same for the host cache's policy, which runs on loader threads.
  std::shared_ptr<SharedEye> host_camera_ = std::make_shared<SharedEye>();
  CameraPredictor predictor_;
  std::uint64_t frame_ = 0;
  bool send_full_ = true;                      // next update carries full arrays
  std::vector<LoadedBrick> staged_;            // loaded, waiting for budget or a free slot
  std::vector<std::uint32_t> pending_nodes_;   // node requests to answer next frame
  std::vector<std::uint32_t> pending_blocks_;  // page-table blocks to allocate next frame
  // Requested bricks -> frame of their first request in an unbroken run of frames (ageing).
  std::unordered_map<BrickKey, std::uint64_t> waiting_since_;
  std::vector<std::byte> scratch_;  // keeps the voxels of this frame's uploads alive
  std::vector<std::shared_ptr<const HostBrick>> upload_data_;
  std::vector<BrickUpload> uploads_;
  FrameTables tables_;
  FrameResult result_;
};

}  // namespace resoct
