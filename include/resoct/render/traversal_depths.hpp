#pragma once
/// The residency traversal's depth rules, on the host: which octree depth a ray descends to for
/// its step, and how deep a level's trilinear samples can be classified. Both depend only on the
/// frame's depth and level tables, so the host computes them once per frame into those tables
/// (ResoctDepthInfo::shortest_side, ResoctLevelInfo::depth_cap) and the kernel reads them, instead
/// of every ray recomputing them from the node extents (kernel/node_class.glsl.h
/// resoct_traversal_depth_for). The visible-subtree builder uses the same functions, so its depth
/// limit is the kernel's by construction.
#include <cstdint>
#include <span>

#include "resoct/kernel/frame.glsl.h"

namespace resoct {

/// The shortest side of a depth's nodes in the frame's box units: min over the axes of the node
/// extent (level-0 voxels) over the level-0 voxels per box unit. A node shorter than a ray's step
/// cannot skip more than one step, so the traversal stops above it.
float node_shortest_side(const kernel::ResoctDepthInfo& depth, const kernel::ResoctFrame& frame);

/// The deepest depth (at least `start`) whose nodes are at least `dt` long on every axis: the
/// traversal depth of a ray with step `dt` (box units).
std::uint32_t traversal_depth(std::span<const kernel::ResoctDepthInfo> depths, std::uint32_t start,
                              const kernel::ResoctFrame& frame, float dt);

/// The deepest depth (at least `start`) whose nodes span at least two voxels per axis of `level`:
/// the extent of one trilinear sample of that level. A smaller node cannot be classified for such
/// a sample (its value depends on voxels beyond the node), and descending to it only adds node
/// visits that grow with the data at a fixed view.
std::uint32_t level_depth_cap(std::span<const kernel::ResoctDepthInfo> depths, std::uint32_t start,
                              const kernel::ResoctLevelInfo& level);

}  // namespace resoct
