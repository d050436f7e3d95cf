#pragma once
// Internal to resoct::core: when the Renderer's visible-subtree bits (FrameTables::
// visible_subtrees, render/visible_subtrees.hpp) must be rebuilt, updated or left alone.
//
// The bits are computed from the octree's records and from what the frame's tables say about
// them (the transfer functions' visible ranges, the start depth, the deepest depth a ray
// descends to, the hidden fraction each depth allows, which follows the shortest step, and the
// depth of each entry's finest bricks). A still
// scene whose cache has converged changes neither, so a steady frame does no work here; node
// answers and brick metadata arriving while a view loads change some records, and only the paths
// above those are computed again (VisibleSubtreeBuilder::update).
#include <cstdint>
#include <vector>

#include "resoct/backend/backend.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/render/visible_subtrees.hpp"

namespace resoct::detail {

class VisibleSubtreeTracker {
 public:
  /// Records what this frame's update sends of the octree: `full` when the backend receives every
  /// word (the bits are rebuilt), otherwise the word deltas, of which only the flags and the value
  /// range of a record (RESOCT_NODE_FLAGS, RESOCT_NODE_MINMAX) matter to the bits. Bricks arriving
  /// change the residency words every frame of a load and leave the bits as they are.
  void note_sent(const OctreeDeltas& deltas, bool full, std::uint32_t node_slots);

  /// Brings tables.visible_subtrees up to date with `octree` (the words as sent) after the rest of
  /// `tables` was built for this frame, with the allowance of `skip_min_samples`
  /// (TuningOptions::skip_min_samples): residency mode only; other modes get none (version 0).
  void refresh(const ResidencyOctree& octree, RenderMode mode, float skip_min_samples,
               FrameTables& tables);

 private:
  // What the bits were built from besides the octree's words.
  struct Key {
    std::uint32_t depth_limit = 0;
    std::uint32_t start_depth = 0;
    std::vector<std::uint32_t> entries;  // per slot-table entry: slot, vis_bins, vis_lo16, vis_hi16
    std::vector<std::uint16_t> allowance;    // per depth: hidden_allowance()
    std::vector<std::uint32_t> brick_depth;  // per entry: brick_depths()
    bool operator==(const Key&) const = default;
  };
  Key key_;
  Key scratch_;  // the key being compared, kept between frames for its capacity
  VisibleSubtreeBuilder builder_;
  bool rebuild_ = true;                       // the whole octree was sent since the last refresh
  std::vector<std::uint32_t> changed_nodes_;  // nodes whose flags or range changed since then
};

}  // namespace resoct::detail
