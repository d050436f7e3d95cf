#pragma once
/// \file
/// Builds the small per-frame tables every backend reads (kernel/frame.glsl.h): camera basis,
/// sampling and LOD constants, the visible-slot table, hierarchy levels, octree depths and the
/// transfer-function LUTs. See docs/rendering.md ("Traversal").

#include <cstdint>

#include "resoct/backend/backend.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/engine/request_set.hpp"
#include "resoct/render/frame_jitter.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct {

/// Frame parameters that are not part of the Scene.
struct FrameOptions {
  RenderMode mode = RenderMode::residency;
  std::uint32_t frame_index = 0;
  RequestStrategy request_strategy = RequestStrategy::global;
  /// Octree depth at which empty-space tests start (clamped to the last depth).
  std::uint32_t start_depth = 0;
  /// Hard cap of march iterations per ray (>= 1); hits are counted, never expected.
  std::uint32_t max_iterations = 1u << 22;
  /// Sub-pixel and sample offsets of an accumulated frame (none by default).
  FrameJitter jitter;
};

/// Fills FrameTables for one frame. Slots are ordered by scene importance (ascending, as the
/// scene defines "lower loads first"), ties by the finer finest level first, then by scene
/// order. `channels` maps each visible channel to its page-table / octree slot; its slot count
/// is the page_slot_count. Every scene channel must be shown in some slot.
/// Throws Error(invalid_argument) naming the parameter when the scene does not fit the volume
/// ("scene"), a channel is not mapped ("channels"), more than RESOCT_MAX_SLOTS channels are
/// visible ("scene.channels"), the layout does not match the hierarchy ("layout"), an extent or
/// node extent does not fit 31 bits ("extent", "layout"), max_iterations is 0
/// ("max_iterations") or the jitter is out of range ("jitter.*", FrameJitter::validate).
/// Thread-safe (pure function of its arguments).
FrameTables build_frame_tables(const Scene& scene, const BrickHierarchy& hierarchy,
                               const OctreeLayout& layout, const ChannelMap& channels,
                               const FrameOptions& options = {});

/// As above, reusing `out`'s vectors (no allocation once they have grown).
void build_frame_tables(const Scene& scene, const BrickHierarchy& hierarchy,
                        const OctreeLayout& layout, const ChannelMap& channels,
                        const FrameOptions& options, FrameTables& out);

}  // namespace resoct
