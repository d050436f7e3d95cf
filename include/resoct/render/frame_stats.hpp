#pragma once
/// \file
/// What one frame of the Renderer did: the backend's ray statistics plus the host-side work
/// (requests, loads, uploads, page updates) and timings.

#include <cstdint>
#include <string>

#include "resoct/backend/backend.hpp"

namespace resoct {

/// Per-frame statistics. Plain value type.
struct FrameStats {
  std::uint64_t frame_index = 0;
  BackendStats backend;  ///< as returned by Backend::render

  // Requests of this frame.
  std::uint64_t brick_requests = 0;     ///< distinct device brick requests returned
  std::uint64_t stale_requests = 0;     ///< dropped: slot remapped since, or invalid key
  std::uint64_t failed_requests = 0;    ///< ignored: the brick failed to load before
  std::uint64_t ancestor_requests = 0;  ///< added host-side by the greedy strategy
  std::uint64_t node_requests = 0;      ///< distinct octree node requests returned
  std::uint64_t nodes_answered = 0;     ///< node metadata records supplied this frame

  // Loading and uploads (applied at the start of this frame).
  std::uint64_t loads_queued = 0;     ///< loader queue after this frame's request
  std::uint64_t loads_in_flight = 0;  ///< bricks being read when the frame ended
  std::uint64_t prefetch_queued = 0;  ///< bricks queued for prefetching this frame
  /// Of them, bricks of the next timepoint (PrefetchOptions::next_timepoint).
  std::uint64_t prefetch_next_timepoint = 0;
  std::uint32_t timepoint = 0;        ///< the timepoint this frame showed
  bool timepoint_switched = false;    ///< the frame began by switching to `timepoint`
  std::uint64_t bricks_uploaded = 0;  ///< cache slots written
  std::uint64_t bytes_uploaded = 0;
  std::uint64_t pages_empty = 0;        ///< bricks mapped EMPTY (all zero) this frame
  std::uint64_t pages_homogeneous = 0;  ///< bricks mapped HOMOGENEOUS this frame
  std::uint64_t uploads_deferred = 0;   ///< loaded bricks waiting for budget or a free slot
  std::uint64_t evictions = 0;
  std::uint64_t insert_failures = 0;  ///< cache inserts refused because every slot was pinned
  std::uint64_t stale_loads = 0;      ///< loaded bricks dropped: channel no longer visible
  std::uint64_t new_failures = 0;     ///< bricks that failed to load, reported this frame
  std::uint64_t page_deltas = 0;      ///< page entries sent (all of them when pages_full)
  std::uint64_t node_deltas = 0;      ///< octree words sent (all of them when nodes_full)
  bool pages_full = false;
  std::uint64_t block_misses = 0;  ///< unallocated page-table blocks reported (allocated now)
  std::uint64_t page_blocks = 0;   ///< page-table pool blocks allocated after the frame
  bool nodes_full = false;

  // Working set: distinct cache slots the backend sampled.
  std::uint64_t working_set_bricks = 0;
  std::uint64_t working_set_bytes = 0;
  std::uint32_t resident_bricks = 0;  ///< cache slots in use after the frame

  // Host wall times in milliseconds.
  double ms_upload = 0.0;    ///< applying loaded bricks to cache, page table and octree
  double ms_update = 0.0;    ///< collecting deltas and Backend::update
  double ms_render = 0.0;    ///< build_frame_tables and Backend::render
  double ms_requests = 0.0;  ///< decoding requests and handing them to the loader
  double ms_frame = 0.0;     ///< the whole render_frame
};

/// `total` divided by the frame's rays (0 without rays): samples, nodes or iterations per ray.
double per_ray(std::uint64_t total, const BackendStats& stats) noexcept;

/// One human-readable line for progress output, e.g.
/// "frame 3: 120 requests, 64 uploaded, 2 deferred, 1.2 ms render".
std::string format_frame_line(const FrameStats& s);

}  // namespace resoct
