#pragma once
/// \file
/// How a Renderer is set up, in three layers: the few choices a viewer makes (ViewerOptions), the
/// expert tuning knobs of the frame loop (TuningOptions), and, for the command-line tools, the
/// backend chosen by name (RendererOptions). docs/api.md has the guide.

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "resoct/backend/backend.hpp"
#include "resoct/cache/eviction.hpp"
#include "resoct/engine/request_strategy.hpp"
#include "resoct/engine/upload_budget.hpp"

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

/// Which pixels a FrameReport carries. Backends render float RGBA; the 8-bit form is what a
/// texture upload or an image file wants, converted by the renderer into a reused buffer.
enum class FrameOutput : std::uint8_t {
  rgba32f,  ///< FrameReport::image only
  rgba8,    ///< FrameReport::rgba8 only (FrameReport::image stays empty)
  both,     ///< both
  /// The float image stays where the backend rendered it: on a device backend (Vulkan) in device
  /// memory, described by FrameReport::device_image, with no copy to the host
  /// (FrameReport::image and ::rgba8 stay empty); on the CPU backend, whose device is the host,
  /// as rgba32f in FrameReport::image.
  device,
};
/// "rgba32f" / "rgba8" / "both" / "device".
const char* to_string(FrameOutput o) noexcept;
/// The inverse of to_string; throws Error(invalid_argument) naming `parameter` otherwise.
FrameOutput parse_frame_output(std::string_view s, std::string_view parameter = "output");

/// max(1, std::thread::hardware_concurrency()): one loader thread per core, the default of
/// ViewerOptions::loader_threads.
std::uint32_t default_loader_threads() noexcept;

/// What a viewer chooses: memory, loading threads, the rendering method and the output form.
struct ViewerOptions {
  std::uint64_t device_cache_bytes = std::uint64_t(512) << 20;  ///< bricks on the device, > 0
  std::uint64_t host_cache_bytes = std::uint64_t(1) << 30;      ///< decoded bricks in host memory
  /// Loader threads; 0 loads synchronously inside render_frame (deterministic), at most 1024.
  std::uint32_t loader_threads = default_loader_threads();
  RenderMode mode = RenderMode::residency;
  RequestStrategy strategy = RequestStrategy::greedy;
  Eviction eviction = Eviction::lru;  ///< device cache
  /// Host cache (the Octreemizer's own cache level: main memory).
  Eviction host_eviction = Eviction::lru;
  PrefetchOptions prefetch;
  /// Bricks whose load failed with an error that may pass (a network or server fault, exhausted
  /// host memory) are loaded again this long after the failure, then after twice as long each
  /// time, up to 32 times (BrickLoader::set_transient_retry); each is still reported once, and a
  /// frame is not converged while a retry is pending. 0 = a failed brick stays failed (its
  /// coarser substitute is final). At most 3600000 (one hour).
  std::uint32_t retry_failed_after_ms = 0;
  FrameOutput output = FrameOutput::rgba32f;
  /// Measure every coarse brick's down-sampling error while loading it (brick_error()), so that
  /// scenes may choose levels by error (Scene::lod_error_color, docs/rendering.md "Error-bounded
  /// LOD"). It costs reading the level-0 bricks under each coarse brick on the loader threads;
  /// off, a scene that asks for error-bounded LOD is refused.
  bool brick_errors = false;
  /// Throws Error(invalid_argument) naming the field.
  void validate() const;
};

/// The frame loop's expert knobs; the defaults suit every dataset the tests and benchmarks use.
/// TuningOptions::skip_min_samples unless set: measured on Table 1 (bench/README.md).
inline constexpr float kDefaultSkipMinSamples = 12.0f;

struct TuningOptions {
  /// Visible channel slots of the page table and octree; 0 = the dataset's channel count,
  /// capped at RESOCT_MAX_SLOTS (32).
  std::uint32_t visible_slots = 0;
  /// Blocks of 16^3 page-table entries the sparse page table may allocate (16 KiB of device
  /// memory each; docs/core-structures.md). 0 = derived: the device cache's slots plus half as
  /// many again (at least 64) of headroom, clamped to the blocks of all tables. Must exceed the
  /// cache slots (so that a block without MAPPED entries can always be reclaimed) unless it
  /// covers every block, and stay below 2^19.
  std::uint32_t page_pool_blocks = 0;
  UploadBudget upload_budget{256, std::numeric_limits<std::uint64_t>::max()};
  std::uint32_t ttl = 2;     ///< frames a fresh upload stays pinned (>= 1)
  glm::uvec3 leaf_size{16};  ///< residency octree leaf, voxels per axis
  std::uint32_t brick_request_capacity = 1u << 16;
  std::uint32_t node_request_capacity = 1u << 14;
  /// Node metadata records (node x assigned slot) supplied per frame; bounds the host time per
  /// frame (a procedural region_meta costs a few microseconds).
  std::uint32_t max_node_answers = 16384;
  std::uint32_t max_iterations = 1u << 20;  ///< march iterations per ray (cap)
  std::uint32_t start_depth = 2;
  /// Residency mode: the fewest samples a ray must save in a node's hidden space for the descent
  /// to look below that node (docs/rendering.md "Visible subtrees"). Where what a subtree hides
  /// would save fewer samples than the decisions that find it cost, the node is marched whole and
  /// its few hidden samples are taken (transparent: the image is the same). 0 = look below every
  /// node that hides anything. Must be finite and >= 0.
  float skip_min_samples = kDefaultSkipMinSamples;
  /// Throws Error(invalid_argument) naming the field.
  void validate() const;
};

/// Everything a Renderer takes. Its fields are those of both layers (`options.ttl`,
/// `options.device_cache_bytes`), so a viewer passes ViewerOptions where RendererOptions is
/// expected, and the tools set any field directly.
struct RendererOptions : ViewerOptions, TuningOptions {
  RendererOptions() = default;
  /// A viewer's choices with default (or given) tuning. Implicit on purpose.
  RendererOptions(const ViewerOptions& viewer, const TuningOptions& tuning = {})  // NOLINT
      : ViewerOptions(viewer), TuningOptions(tuning) {}

  /// Name-based backend creation (create_backend()), used by the Renderer constructor that takes
  /// no backend object; the command-line tools choose backends this way.
  std::string backend = "cpu";
  BackendOptions backend_options;
  /// Both layers' checks; throws Error(invalid_argument) naming the field.
  void validate() const;
};

}  // namespace resoct
