#pragma once
// Internal to resoct::core: the state behind Renderer (renderer.hpp) and the frame loop's
// steps. renderer.cpp runs the frame loop, renderer_setup.cpp builds the engine from the
// options, renderer_inspection.cpp exposes it to tests and tools (resoct::inspect).
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/cache/wish_list_distance.hpp"
#include "resoct/engine/brick_cache.hpp"
#include "resoct/engine/brick_loader.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/prefetch.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/render/frame_tables.hpp"
#include "resoct/render/renderer.hpp"
#include "visible_subtree_tracker.hpp"

namespace resoct {

namespace detail {

/// A camera position read by loader threads (host cache Octreemizer distances).
struct SharedEye {
  std::mutex mutex;
  glm::dvec3 eye{0.0};
};

/// The last frame's wish list tree, read by the caches' published Octreemizer policies (the host
/// cache's on loader threads): each frame publishes a new immutable tree.
struct SharedWishList {
  std::mutex mutex;
  std::shared_ptr<const WishListDistance> tree;  // null before the first frame: every d is 0
  double distance(BrickKey key) {
    std::shared_ptr<const WishListDistance> t;
    {
      std::lock_guard lock(mutex);
      t = tree;
    }
    return t ? double(t->distance(key)) : 0.0;
  }
};

/// Whether a page-table entry is UNMAPPED (neither a cache slot nor EMPTY / HOMOGENEOUS).
inline bool page_unmapped(std::uint32_t entry) {
  return kernel::resoct_page_state(entry) == kernel::RESOCT_PAGE_STATE_UNMAPPED;
}

}  // namespace detail

// The Renderer's state and the frame loop's steps; the Renderer forwards to it.
struct Renderer::Impl {
  Impl(std::shared_ptr<const BrickSource> source, std::unique_ptr<Backend> backend,
       RendererOptions options);

  std::uint32_t timepoints() const noexcept { return source_->timepoints(); }
  void render_frame(const Scene& scene, FrameReport& report, const FrameJitter& jitter);

  const FrameTables& frame_tables(const Scene& scene, const FrameJitter& jitter);
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
  // The published Octreemizer priority is in use (device or host cache): wish_keys_ is collected
  // and published as the wish list tree after each frame.
  bool uses_wish_list() const noexcept;
  void publish_wish_list();
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
  std::shared_ptr<detail::SharedEye> host_camera_ = std::make_shared<detail::SharedEye>();
  // The wish list tree of the published Octreemizer priority (Eviction::octreemizer), and this
  // frame's wish list while it is collected (sampled bricks, then requested ones).
  std::shared_ptr<detail::SharedWishList> wish_list_ = std::make_shared<detail::SharedWishList>();
  std::vector<BrickKey> wish_keys_;
  CameraPredictor predictor_;
  std::uint64_t frame_ = 0;
  // loader_threads = 0: bricks the frame's requests loaded synchronously (of the brick budget).
  std::size_t sync_loaded_ = 0;
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
  detail::VisibleSubtreeTracker visible_subtrees_;  // tables_.visible_subtrees kept current
  FrameResult result_;
};

}  // namespace resoct
