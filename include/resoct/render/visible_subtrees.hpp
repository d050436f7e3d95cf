#pragma once
/// Visible subtrees: per octree node and slot-table entry, whether the residency traversal's
/// descent could find no node below it that its transfer function hides (docs/rendering.md
/// "Visible subtrees"). The descent stops at such a node and marches its whole box as one visible
/// node: no classification, run look-ahead or decision at the finer nodes inside it, which are
/// where the residency mode lost time against the page table when nothing can be culled.
///
/// A node's bit is a frame's fact, not the octree's: it depends on the transfer functions (an
/// EMPTY node is one the function hides) and on the node records, so the renderer builds the bits
/// when either changes (Renderer, FrameTables::visible_subtrees), from the same words the backend
/// holds. Built on the host: a pass over the nodes above the frame's deepest traversal depth,
/// not a per-ray cost.
#include <cstdint>
#include <span>
#include <vector>

#include "resoct/backend/backend.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/kernel/frame.glsl.h"

namespace resoct {

/// The deepest octree depth any ray of a frame built from `frame` and `depths` descends to in
/// residency mode: the traversal depth of the shortest step a ray can have (an axis-aligned ray
/// at the finest voxel size, rounded to its step level as the kernel does) capped by the depth at
/// which nodes span two voxels of the finest level any of `slots` samples
/// (kernel/node_class.glsl.h resoct_traversal_depth, resoct_level_depth_cap). Every ray's
/// traversal depth is at most this, since both depths only shrink as the step and level grow.
std::uint32_t deepest_traversal_depth(const kernel::ResoctFrame& frame,
                                      std::span<const kernel::ResoctLevelInfo> levels,
                                      std::span<const kernel::ResoctDepthInfo> depths,
                                      std::span<const kernel::ResoctSlotInfo> slots);

/// Builds one word per octree node into `out` (resized to the node count of `depths`): bit i is
/// set when slot-table entry i (i < RESOCT_MAX_SLOTS; later entries, a lens's second bank, get no
/// bit) has, at that node and at every node below it down to `depth_limit`:
/// - a record with metadata (not INVALID: the descent would request it, and its answer may cull),
/// - a value range the entry's transfer function shows (not EMPTY: the descent would skip it),
/// and the node's own record is not homogeneous (a homogeneous node's value is used without
/// sampling; homogeneous nodes below are sampled instead, to the same values). Nodes wholly
/// outside the volume [0, `extent`) (level-0 voxels), which no ray reaches, count as shown. Nodes
/// at depths below `start_depth` or at and below `depth_limit` get 0. `words` are
/// ResidencyOctree::words() with `node_slots` records per node (kernel/octree_node.glsl.h).
/// Throws Error(invalid_argument) naming "octree" when `words` is shorter than the depth table's
/// nodes, or "slots" when an entry names a slot at or past `node_slots`.
void build_visible_subtrees(std::span<const std::uint32_t> words, std::uint32_t node_slots,
                            std::span<const kernel::ResoctDepthInfo> depths,
                            std::span<const kernel::ResoctSlotInfo> slots, glm::uvec3 extent,
                            std::uint32_t start_depth, std::uint32_t depth_limit,
                            std::vector<std::uint32_t>& out);

/// The bits of residency-mode tables from the octree a backend holds (its words as sent): fills
/// tables.visible_subtrees for the depths above deepest_traversal_depth() and gives them a new
/// FrameTables::visible_subtrees_version; for other modes clears them (version 0).
void build_visible_subtrees(const ResidencyOctree& octree, FrameTables& tables);

}  // namespace resoct
