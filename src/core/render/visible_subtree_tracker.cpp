#include "visible_subtree_tracker.hpp"

#include <utility>

#include "resoct/kernel/octree_node.glsl.h"

namespace resoct::detail {

void VisibleSubtreeTracker::note_sent(const OctreeDeltas& deltas, bool full,
                                      std::uint32_t node_slots) {
  if (full) {
    rebuild_ = true;
    changed_nodes_.clear();  // a rebuild covers them
    return;
  }
  if (rebuild_) return;
  const std::uint32_t record_words = kernel::RESOCT_NODE_WORDS * node_slots;
  for (const OctreeWordDelta& d : deltas.words) {
    // Flags and ranges decide what a node hides; residency words whether a hidden node of only
    // zeros is resident EMPTY pages (VisibleSubtreeBuilder::empty_pages); the builder does not
    // read the occupancy word.
    const std::uint32_t which = d.index % kernel::RESOCT_NODE_WORDS;
    if (which != kernel::RESOCT_NODE_OCCUPANCY) changed_nodes_.push_back(d.index / record_words);
  }
}

void VisibleSubtreeTracker::refresh(const ResidencyOctree& octree, RenderMode mode,
                                    float skip_min_samples, FrameTables& tables) {
  if (mode != RenderMode::residency) {
    build_visible_subtrees(octree, tables);  // clears them
    changed_nodes_.clear();
    return;
  }
  // This frame's key is built in a kept buffer: a steady frame allocates nothing here.
  Key& key = scratch_;
  key.depth_limit =
      deepest_traversal_depth(tables.frame, tables.levels, tables.depths, tables.slots);
  key.start_depth = tables.frame.start_depth;
  hidden_allowance(tables.frame, tables.depths, skip_min_samples, key.allowance);
  brick_depths(tables.levels, tables.slots, key.brick_depth);
  key.entries.clear();
  for (const kernel::ResoctSlotInfo& s : tables.slots) {
    key.entries.insert(key.entries.end(), {s.slot, s.vis_bins, s.vis_lo16, s.vis_hi16});
  }
  if (rebuild_ || key != key_ || tables.visible_subtrees_version == 0) {
    builder_.build(octree, tables, key.depth_limit, key.allowance, key.brick_depth);
    std::swap(key_, scratch_);
    rebuild_ = false;
  } else if (!changed_nodes_.empty()) {
    builder_.update(octree, changed_nodes_, tables);
  }
  changed_nodes_.clear();
}

}  // namespace resoct::detail
