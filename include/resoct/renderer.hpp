#pragma once
/// \file
/// The frame loop: owns the host-side residency state (page table, brick cache, residency
/// octree, channel map), a BrickLoader and a Backend, and turns a Scene into images frame by
/// frame (docs/architecture.md §2). See docs/renderer.md.

#include <cstdint>
#include <functional>
#include <limits>
#include <algorithm>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/backend.hpp"
#include "resoct/brick_cache.hpp"
#include "resoct/brick_loader.hpp"
#include "resoct/brick_source.hpp"
#include "resoct/channel_map.hpp"
#include "resoct/frame_stats.hpp"
#include "resoct/hierarchy.hpp"
#include "resoct/octree_layout.hpp"
#include "resoct/page_table.hpp"
#include "resoct/prefetch.hpp"
#include "resoct/request_set.hpp"
#include "resoct/residency_octree.hpp"
#include "resoct/scene.hpp"

namespace resoct {

/// Prefetching ahead of camera motion (paper 001; docs/renderer.md, "Prefetching"). Each frame
/// the camera's next `lookahead_frames` poses are extrapolated linearly from its last two, and
/// up to `max_bricks` / `max_bytes` (padded voxel bytes) bricks those views may need and that are
/// neither on the device nor in the host cache are queued for loading into the host cache, below
/// every real request.
///
/// Playing a time series (`next_timepoint`): each frame also queues, below the camera's
/// prefetches, up to the same budget of bricks of the next timepoint (scene timepoint + 1,
/// wrapping to 0) that the current view may need and the host cache lacks, so that switching to
/// it is served from host memory (docs/renderer.md "Time series").
struct PrefetchOptions {
  std::uint32_t lookahead_frames = 0;                 ///< 0 disables prefetching; at most 64
  std::uint32_t max_bricks = 64;                      ///< per frame, > 0 when enabled
  std::uint64_t max_bytes = std::uint64_t(64) << 20;  ///< per frame, > 0 when enabled
  bool next_timepoint = false;  ///< prefetch the next timepoint (no effect without a t axis)
};

/// Construction parameters of a Renderer; validate() names the offending field.
struct RendererOptions {
  std::string backend = "cpu";  ///< a name registered with register_backend()
  BackendOptions backend_options;
  /// Visible channel slots of the page table and octree; 0 = the dataset's channel count,
  /// capped at RESOCT_MAX_SLOTS (32).
  std::uint32_t visible_slots = 0;
  std::uint64_t device_cache_bytes = std::uint64_t(512) << 20;
  /// Blocks of 16^3 page-table entries the sparse page table may allocate (16 KiB of device
  /// memory each; docs/core-structures.md). 0 = derived: the device cache's slots plus half as
  /// many again (at least 64) of headroom, clamped to the blocks of all tables. Must exceed the
  /// cache slots (so that a block without MAPPED entries can always be reclaimed) unless it
  /// covers every block, and stay below 2^19.
  std::uint32_t page_pool_blocks = 0;
  std::uint64_t host_cache_bytes = std::uint64_t(1) << 30;
  UploadBudget upload_budget{256, std::numeric_limits<std::uint64_t>::max()};
  std::uint32_t ttl = 2;         ///< frames a fresh upload stays pinned (>= 1)
  std::string eviction = "lru";  ///< device cache: "lru" or "octreemizer"
  /// Host cache (decoded bricks): "lru" or "octreemizer" (distance from the current camera).
  std::string host_eviction = "lru";
  PrefetchOptions prefetch;
  glm::uvec3 leaf_size{16};  ///< residency octree leaf, voxels per axis
  RenderMode mode = RenderMode::residency;
  RequestStrategy strategy = RequestStrategy::greedy;
  /// Bricks whose load failed with an error that may pass (a network or server fault, exhausted
  /// host memory) are loaded again this long after the failure, then after twice as long each
  /// time, up to 32 times (BrickLoader::set_transient_retry); each is still reported once, and a
  /// frame is not converged while a retry is pending. 0 = a failed brick stays failed (its
  /// coarser substitute is final). At most 3600000 (one hour).
  std::uint32_t retry_failed_after_ms = 0;
  /// Loader threads; 0 loads synchronously inside render_frame (deterministic).
  std::uint32_t loader_threads = std::max(1u, std::thread::hardware_concurrency());
  std::uint32_t brick_request_capacity = 1u << 16;
  std::uint32_t node_request_capacity = 1u << 14;
  /// Node metadata records (node x assigned slot) supplied per frame; bounds the host time per
  /// frame (a procedural region_meta costs a few microseconds).
  std::uint32_t max_node_answers = 16384;
  std::uint32_t max_iterations = 1u << 20;  ///< march iterations per ray (cap)
  std::uint32_t start_depth = 2;
  /// Throws Error(invalid_argument) naming the field.
  void validate() const;
};

/// One rendered frame.
struct FrameReport {
  Image image;
  /// True when the frame needed nothing it did not have: no brick or node requests other than
  /// for bricks that failed to load (for good: no retry pending), no dropped requests, nothing
  /// queued, loading or waiting.
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
  /// Validates the options, creates the backend (Error(invalid_argument) naming "backend" if
  /// unknown), builds the host structures and configures the backend. Throws Error naming
  /// "source" when it is null, or as the structures' constructors do.
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
  /// Renders until a frame reports converged or `max_frames` frames were rendered (>= 1).
  ConvergeReport render_until_converged(const Scene& scene, std::uint32_t max_frames);

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
  const FrameTables& frame_tables(const Scene& scene);
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
