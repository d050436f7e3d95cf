#pragma once
/// \file
/// Builds the small per-frame tables (backend.hpp FrameTables) from a scene and the host
/// structures. Implemented with the traversal kernel.

#include <cstdint>

#include "resoct/backend.hpp"
#include "resoct/channel_map.hpp"
#include "resoct/hierarchy.hpp"
#include "resoct/octree_layout.hpp"
#include "resoct/scene.hpp"

namespace resoct {

/// The frame record, slot, level and depth tables and transfer-function LUTs of one frame.
FrameTables build_frame_tables(const Scene& scene, const BrickHierarchy& hierarchy,
                               const OctreeLayout& layout, const ChannelMap& channels,
                               RenderMode mode, std::uint64_t frame_index);

}  // namespace resoct
