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

/// What VisibleSubtreeBuilder::update() did.
struct VisibleSubtreeUpdate {
  std::uint64_t recomputed = 0;     ///< nodes whose mask and word were computed again
  std::uint64_t words_changed = 0;  ///< of those, nodes whose word changed
};

/// build_visible_subtrees kept up to date across frames. Beside the bits it keeps, per node, the
/// entries whose whole subtree (down to the depth limit) has metadata and is shown. When only some
/// records change (node answers and brick metadata arriving while a view loads), update()
/// recomputes those nodes and the ancestors whose mask changes, instead of every node above the
/// depth limit (millions on a 2048³ volume with 16³ leaves).
class VisibleSubtreeBuilder {
 public:
  /// build_visible_subtrees into `out`, remembering the parameters and the per-node masks.
  void build(std::span<const std::uint32_t> words, std::uint32_t node_slots,
             std::span<const kernel::ResoctDepthInfo> depths,
             std::span<const kernel::ResoctSlotInfo> slots, glm::uvec3 extent,
             std::uint32_t start_depth, std::uint32_t depth_limit, std::vector<std::uint32_t>& out);

  /// After the records of `nodes` (flat node indices, in any order, repeats allowed) changed in
  /// `words`: brings `out`, as the last build() or update() left it, to what build() with the
  /// same parameters would give now. Throws Error(invalid_argument) naming "octree" before any
  /// build(), or when `words` or `out` do not fit the built tree, and "nodes" for an index past it.
  VisibleSubtreeUpdate update(std::span<const std::uint32_t> words,
                              std::span<const std::uint32_t> nodes,
                              std::vector<std::uint32_t>& out);

  /// build() for residency-mode tables over the octree a backend holds, with `depth_limit` from
  /// deepest_traversal_depth(); a new FrameTables::visible_subtrees_version.
  void build(const ResidencyOctree& octree, FrameTables& tables, std::uint32_t depth_limit);
  /// update() of tables.visible_subtrees after the records of `nodes` changed; a new version
  /// when any word changed.
  VisibleSubtreeUpdate update(const ResidencyOctree& octree, std::span<const std::uint32_t> nodes,
                              FrameTables& tables);

 private:
  struct NodeResult {
    std::uint32_t ok;    // entries whose subtree, this node included, has metadata and is shown
    std::uint32_t bits;  // the node's word
  };
  NodeResult compute(std::span<const std::uint32_t> words, std::uint32_t depth,
                     std::uint32_t local) const;

  std::uint32_t node_slots_ = 0;
  std::vector<kernel::ResoctDepthInfo> depths_;
  std::vector<kernel::ResoctSlotInfo> slots_;  // the first RESOCT_MAX_SLOTS entries
  glm::uvec3 extent_{0};
  std::uint32_t start_depth_ = 0;
  std::uint32_t depth_limit_ = 0;
  std::uint32_t shown_ = 0;                 // entries whose transfer function shows anything
  std::vector<std::uint8_t> some_outside_;  // per depth: whether any node lies outside the volume
  std::vector<std::uint32_t> ok_;           // per node at depths [start, limit]: NodeResult::ok
  std::uint64_t nodes_ = 0;                 // nodes of the tree (0: not built)
  std::vector<std::vector<std::uint32_t>> pending_;  // update(): nodes to recompute, per depth
};

}  // namespace resoct
