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
#include "resoct/render/renderer_options.hpp"

namespace resoct {

/// The shortest step any ray of a frame built from `frame` takes, in box units: an axis-aligned
/// ray's at the finest voxel size, rounded to its step level as the kernel rounds
/// (kernel/step.glsl.h resoct_step_size, kernel/step_lut.glsl.h).
float shortest_step(const kernel::ResoctFrame& frame);

/// The deepest octree depth any ray of a frame built from `frame` and `depths` descends to in
/// residency mode: the traversal depth of the shortest step a ray can have (an axis-aligned ray
/// at the finest voxel size, rounded to its step level as the kernel does) capped by the depth at
/// which nodes span two voxels of the finest level any of `slots` samples
/// (render/traversal_depths.hpp, which the frame's tables and so the kernel follow). Every ray's
/// traversal depth is at most this, since both depths only shrink as the step and level grow.
std::uint32_t deepest_traversal_depth(const kernel::ResoctFrame& frame,
                                      std::span<const kernel::ResoctLevelInfo> levels,
                                      std::span<const kernel::ResoctDepthInfo> depths,
                                      std::span<const kernel::ResoctSlotInfo> slots);

/// A node's hidden fraction, of 65535: the share of its volume, down to the depth limit, whose
/// records an entry's transfer function hides (EMPTY). 65535 for an EMPTY node, 0 at the depth
/// limit's shown nodes, and above them the mean of the children's, rounded up (so that only a
/// subtree hiding nothing has 0). Nodes outside the volume count as hiding nothing.
inline constexpr std::uint32_t kHiddenWhole = 65535u;

/// Per depth of `depths`: the largest hidden fraction (of kHiddenWhole) a node at that depth may
/// have and still get its bit, so that the samples its hidden space would save a ray crossing it
/// are fewer than `skip_min_samples`. A ray crosses a node in at most (its shortest side) /
/// shortest_step() samples, the fraction h of them hidden: the allowance is skip_min_samples /
/// that, rounded down. All 0 when `skip_min_samples` is 0 (a bit only where nothing is hidden).
/// Into `out` (resized; its capacity kept, so that a steady frame allocates nothing).
void hidden_allowance(const kernel::ResoctFrame& frame,
                      std::span<const kernel::ResoctDepthInfo> depths, float skip_min_samples,
                      std::vector<std::uint16_t>& out);

/// Per slot-table entry: the depth whose nodes are the bricks of the finest level the entry
/// samples (ResoctLevelInfo::node_depth), or 0xFFFFFFFF (every depth) when none matches them. A
/// hidden node at or above that depth holds whole bricks that no descent reads; sampling it below a
/// widened bit would request them, so it keeps its ancestors' bits cleared whatever the allowance.
/// Into `out` (resized, capacity kept).
void brick_depths(std::span<const kernel::ResoctLevelInfo> levels,
                  std::span<const kernel::ResoctSlotInfo> slots, std::vector<std::uint32_t>& out);

/// Builds one word per octree node into `out` (resized to the node count of `depths`): bit i is
/// set when slot-table entry i (i < RESOCT_MAX_SLOTS; later entries, a lens's second bank, get no
/// bit) has
/// - at the node, a record with a value range the entry's transfer function shows (not EMPTY)
///   that is not homogeneous (a homogeneous node's value is used without sampling; homogeneous
///   nodes below are sampled instead, to the same values),
/// - at every node below it down to `depth_limit` that is not inside an EMPTY one, a record
///   with metadata (not INVALID: the descent would request it, and its answer may cull),
/// - a hidden fraction (kHiddenWhole) of at most `allowance` at its depth (empty: 0, nothing
///   below hidden; hidden_allowance()), and no hidden node below at a depth at or above the
///   entry's `brick_depth` (brick_depths(); empty: none such). A hidden node below a set bit is
///   sampled instead of skipped, and its samples are transparent; being smaller than a brick, it
///   lies inside one whose record is not hidden. A hidden node of whole bricks of the finest level
///   that are resident EMPTY pages, the coarser levels' bricks there resident too (a VALID [0, 0]
///   record, the entry's zero_value 0, and at the brick depth a residency word with every level
///   from the entry's finest to its coarsest; above it, every child such a node), hides nothing
///   and blocks nothing: a march skips those bricks at their page entries, requesting nothing.
/// Nodes wholly outside the volume [0, `extent`) (level-0 voxels), which no ray reaches, count as
/// shown. Nodes at depths below `start_depth` or at and below `depth_limit` get 0. `words` are
/// ResidencyOctree::words() with `node_slots` records per node (kernel/octree_node.glsl.h).
/// Throws Error(invalid_argument) naming "octree" when `words` is shorter than the depth table's
/// nodes, "slots" when an entry names a slot at or past `node_slots`, "allowance" when it is
/// neither empty nor one value per depth, or "brick_depth" when it is neither empty nor one
/// value per entry.
void build_visible_subtrees(std::span<const std::uint32_t> words, std::uint32_t node_slots,
                            std::span<const kernel::ResoctDepthInfo> depths,
                            std::span<const kernel::ResoctSlotInfo> slots, glm::uvec3 extent,
                            std::uint32_t start_depth, std::uint32_t depth_limit,
                            std::vector<std::uint32_t>& out,
                            std::span<const std::uint16_t> allowance = {},
                            std::span<const std::uint32_t> brick_depth = {});

/// The bits of residency-mode tables from the octree a backend holds (its words as sent): fills
/// tables.visible_subtrees for the depths above deepest_traversal_depth(), with the allowance of
/// `skip_min_samples` (TuningOptions::skip_min_samples), and gives them a new
/// FrameTables::visible_subtrees_version; for other modes clears them (version 0).
void build_visible_subtrees(const ResidencyOctree& octree, FrameTables& tables,
                            float skip_min_samples = kDefaultSkipMinSamples);

/// What VisibleSubtreeBuilder::update() did.
struct VisibleSubtreeUpdate {
  std::uint64_t recomputed = 0;     ///< nodes whose mask and word were computed again
  std::uint64_t words_changed = 0;  ///< of those, nodes whose word changed
};

/// build_visible_subtrees kept up to date across frames. Beside the bits it keeps, per node, the
/// entries whose subtree (down to the depth limit) has metadata, and each entry's hidden fraction.
/// When only some records change (node answers and brick metadata arriving while a view loads),
/// update() recomputes those nodes and the ancestors whose mask or fractions change, instead of
/// every node above the depth limit (millions on a 2048³ volume with 16³ leaves).
class VisibleSubtreeBuilder {
 public:
  /// build_visible_subtrees into `out`, remembering the parameters and the per-node masks.
  void build(std::span<const std::uint32_t> words, std::uint32_t node_slots,
             std::span<const kernel::ResoctDepthInfo> depths,
             std::span<const kernel::ResoctSlotInfo> slots, glm::uvec3 extent,
             std::uint32_t start_depth, std::uint32_t depth_limit, std::vector<std::uint32_t>& out,
             std::span<const std::uint16_t> allowance = {},
             std::span<const std::uint32_t> brick_depth = {});

  /// After the records of `nodes` (flat node indices, in any order, repeats allowed) changed in
  /// `words`: brings `out`, as the last build() or update() left it, to what build() with the
  /// same parameters would give now. Throws Error(invalid_argument) naming "octree" before any
  /// build(), or when `words` or `out` do not fit the built tree, and "nodes" for an index past it.
  VisibleSubtreeUpdate update(std::span<const std::uint32_t> words,
                              std::span<const std::uint32_t> nodes,
                              std::vector<std::uint32_t>& out);

  /// build() for residency-mode tables over the octree a backend holds, with `depth_limit` from
  /// deepest_traversal_depth(), `allowance` from hidden_allowance() and `brick_depth` from
  /// brick_depths(); a new FrameTables::visible_subtrees_version.
  void build(const ResidencyOctree& octree, FrameTables& tables, std::uint32_t depth_limit,
             std::span<const std::uint16_t> allowance, std::span<const std::uint32_t> brick_depth);
  /// update() of tables.visible_subtrees after the records of `nodes` changed; a new version
  /// when any word changed.
  VisibleSubtreeUpdate update(const ResidencyOctree& octree, std::span<const std::uint32_t> nodes,
                              FrameTables& tables);

 private:
  bool empty_pages(std::span<const std::uint32_t> words, std::uint32_t base, std::uint32_t depth,
                   std::uint32_t i, bool inner, std::uint32_t first, std::uint32_t children) const;
  struct NodeResult {
    std::uint32_t known;    // entries whose subtree, this node included, has metadata
    std::uint32_t blocked;  // entries with a hidden node of whole bricks in the subtree
    std::uint32_t bits;     // the node's word
  };
  // The node's result; its hidden fractions go to `hidden` (one per entry). Reads the children's.
  NodeResult compute(std::span<const std::uint32_t> words, std::uint32_t depth, std::uint32_t local,
                     std::uint16_t* hidden) const;

  std::uint32_t node_slots_ = 0;
  std::vector<kernel::ResoctDepthInfo> depths_;
  std::vector<kernel::ResoctSlotInfo> slots_;  // the first RESOCT_MAX_SLOTS entries
  std::vector<std::uint16_t> allowance_;       // per depth (hidden_allowance())
  std::vector<std::uint32_t> brick_depth_;     // per entry (brick_depths()); empty: none
  glm::uvec3 extent_{0};
  std::uint32_t start_depth_ = 0;
  std::uint32_t depth_limit_ = 0;
  std::uint32_t shown_ = 0;                 // entries whose transfer function shows anything
  std::vector<std::uint8_t> some_outside_;  // per depth: whether any node lies outside the volume
  std::vector<std::uint32_t> known_;        // per node at depths [start, limit]: NodeResult::known
  std::vector<std::uint32_t> blocked_;      // and NodeResult::blocked
  std::vector<std::uint16_t> hidden_;       // per node and entry (node-major): hidden fraction
  std::uint64_t nodes_ = 0;                 // nodes of the tree (0: not built)
  std::vector<std::vector<std::uint32_t>> pending_;  // update(): nodes to recompute, per depth
};

}  // namespace resoct
