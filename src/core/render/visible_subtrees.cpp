#include "resoct/render/visible_subtrees.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/kernel/octree_node.glsl.h"

namespace resoct {

namespace {

namespace k = kernel;

// Deepest depth (at least start) whose nodes are at least `dt` long on every axis: the kernel's
// resoct_traversal_depth_for over the host's depth table.
std::uint32_t traversal_depth(std::span<const k::ResoctDepthInfo> depths, std::uint32_t start,
                              const k::ResoctFrame& f, float dt) {
  std::uint32_t depth = start;
  for (std::uint32_t d = start + 1; d < depths.size(); ++d) {
    const k::ResoctDepthInfo& D = depths[d];
    const float sx = float(D.node_extent_x) / f.voxels_per_box_x;
    const float sy = float(D.node_extent_y) / f.voxels_per_box_y;
    const float sz = float(D.node_extent_z) / f.voxels_per_box_z;
    if (std::min(sx, std::min(sy, sz)) < dt) break;
    depth = d;
  }
  return depth;
}

// Deepest depth (at least start) whose nodes span two voxels of a level with these factors: the
// kernel's resoct_level_depth_cap.
std::uint32_t level_depth_cap(std::span<const k::ResoctDepthInfo> depths, std::uint32_t start,
                              const k::ResoctLevelInfo& L) {
  std::uint32_t depth = start;
  for (std::uint32_t d = start + 1; d < depths.size(); ++d) {
    const k::ResoctDepthInfo& D = depths[d];
    if ((D.node_extent_x >> L.factor_log2_x) < 2u || (D.node_extent_y >> L.factor_log2_y) < 2u ||
        (D.node_extent_z >> L.factor_log2_z) < 2u) {
      break;
    }
    depth = d;
  }
  return depth;
}

// Whether the record of `slot` at `node` has metadata and a range `entry` shows; sets
// `homogeneous` when the record is VALID with min = max (kernel/node_class.glsl.h
// resoct_node_class).
bool record_shown(std::span<const std::uint32_t> words, std::uint32_t node,
                  const k::ResoctSlotInfo& entry, std::uint32_t node_slots, bool& homogeneous) {
  const std::uint32_t base = k::resoct_node_base(node, entry.slot, node_slots);
  const std::uint32_t state = k::resoct_node_state(words[base + k::RESOCT_NODE_FLAGS]);
  if (state == k::RESOCT_NODE_INVALID) return false;
  const std::uint32_t minmax = words[base + k::RESOCT_NODE_MINMAX];
  if (!k::resoct_node_range_visible(minmax, entry.vis_lo16, entry.vis_hi16, entry.vis_bins)) {
    return false;
  }
  homogeneous =
      state == k::RESOCT_NODE_VALID && k::resoct_node_min16(minmax) == k::resoct_node_max16(minmax);
  return true;
}

// The coordinate a local index holds in the bits `mask` (ResoctDepthInfo::axis_bits_*): the
// mask's bits from the lowest up are the coordinate's from its least significant bit.
std::uint32_t extract_bits(std::uint32_t local, std::uint32_t mask) {
  std::uint32_t out = 0;
  for (std::uint32_t bit = 0; mask != 0u; mask &= mask - 1u, ++bit) {
    if ((local & mask & (~mask + 1u)) != 0u) out |= 1u << bit;
  }
  return out;
}

// Whether the node's box lies wholly outside the volume [0, extent): the octree's node counts are
// powers of two, so its last nodes along an axis may hold no voxel. No ray reaches them (rays are
// clipped to the volume) and their records stay INVALID: they must not clear their ancestors' bits.
bool outside_volume(const k::ResoctDepthInfo& D, std::uint32_t local, glm::uvec3 extent) {
  return std::uint64_t(extract_bits(local, D.axis_bits_x)) * D.node_extent_x >= extent.x ||
         std::uint64_t(extract_bits(local, D.axis_bits_y)) * D.node_extent_y >= extent.y ||
         std::uint64_t(extract_bits(local, D.axis_bits_z)) * D.node_extent_z >= extent.z;
}

// A process-wide counter: two producers never hand one backend equal versions of different bits.
std::uint64_t next_visible_subtrees_version() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

std::uint32_t deepest_traversal_depth(const k::ResoctFrame& f,
                                      std::span<const k::ResoctLevelInfo> levels,
                                      std::span<const k::ResoctDepthInfo> depths,
                                      std::span<const k::ResoctSlotInfo> slots) {
  if (depths.empty()) return 0;
  const std::uint32_t start =
      std::min<std::uint32_t>(f.start_depth, std::uint32_t(depths.size()) - 1);
  // The kernel's step (kernel/step.glsl.h resoct_step_size) is min_i h_i / |d_i| over the axes,
  // which for a unit direction is at least min_i h_i: an axis-aligned ray has the shortest. Its
  // step level rounds it down as the kernel does (kernel/step_lut.glsl.h), a monotone rounding.
  float dt = std::min(f.finest_voxel_x, std::min(f.finest_voxel_y, f.finest_voxel_z));
  dt = std::max(dt * f.step_scale, f.min_step);
  if (f.step_level_count != 0u) {
    const float ratio = dt * (1.0f / f.ref_step);
    const std::uint32_t level =
        (std::bit_cast<std::uint32_t>(ratio) >> f.step_level_shift) - f.step_level_first;
    if (level < f.step_level_count) {
      dt = std::bit_cast<float>((f.step_level_first + level) << f.step_level_shift) * f.ref_step;
    }
  }
  std::uint32_t depth = traversal_depth(depths, start, f, dt);
  // The finest level any entry samples gives the deepest level cap.
  std::uint32_t finest = 0xFFFFFFFFu;
  for (const k::ResoctSlotInfo& s : slots) {
    if (s.vis_bins != 0u) finest = std::min(finest, s.finest_level);
  }
  if (finest < levels.size())
    depth = std::min(depth, level_depth_cap(depths, start, levels[finest]));
  return depth;
}

void build_visible_subtrees(std::span<const std::uint32_t> words, std::uint32_t node_slots,
                            std::span<const k::ResoctDepthInfo> depths,
                            std::span<const k::ResoctSlotInfo> slots, glm::uvec3 extent,
                            std::uint32_t start_depth, std::uint32_t depth_limit,
                            std::vector<std::uint32_t>& out) {
  VisibleSubtreeBuilder().build(words, node_slots, depths, slots, extent, start_depth, depth_limit,
                                out);
}

void build_visible_subtrees(const ResidencyOctree& octree, FrameTables& tables) {
  if (tables.frame.mode != k::RESOCT_MODE_RESIDENCY) {
    tables.visible_subtrees.clear();
    tables.visible_subtrees_version = 0;
    return;
  }
  VisibleSubtreeBuilder().build(
      octree, tables,
      deepest_traversal_depth(tables.frame, tables.levels, tables.depths, tables.slots));
}

// A node's mask and word from its record and its children's masks (the children's first, when
// the node is above the depth limit). The limit's own nodes are checked but their children are
// not: no ray descends past them, and they get no word.
VisibleSubtreeBuilder::NodeResult VisibleSubtreeBuilder::compute(
    std::span<const std::uint32_t> words, std::uint32_t depth, std::uint32_t local) const {
  const k::ResoctDepthInfo& D = depths_[depth];
  if (some_outside_[depth] != 0u && outside_volume(D, local, extent_)) return {shown_, 0u};
  std::uint32_t ok = shown_;
  if (depth < depth_limit_) {
    const k::ResoctDepthInfo& below = depths_[depth + 1];
    const std::uint32_t first = below.first_node + (local << below.child_shift);
    for (std::uint32_t c = 0; c < (1u << below.child_shift); ++c) ok &= ok_[first + c];
  }
  std::uint32_t bits = 0;
  for (std::uint32_t pending = ok; pending != 0u; pending &= pending - 1u) {
    const std::uint32_t i = std::uint32_t(std::countr_zero(pending));
    bool homogeneous = false;
    if (!record_shown(words, D.first_node + local, slots_[i], node_slots_, homogeneous)) {
      ok &= ~(1u << i);
    } else if (!homogeneous) {
      bits |= 1u << i;
    }
  }
  return {ok, depth < depth_limit_ ? bits : 0u};
}

void VisibleSubtreeBuilder::build(std::span<const std::uint32_t> words, std::uint32_t node_slots,
                                  std::span<const k::ResoctDepthInfo> depths,
                                  std::span<const k::ResoctSlotInfo> slots, glm::uvec3 extent,
                                  std::uint32_t start_depth, std::uint32_t depth_limit,
                                  std::vector<std::uint32_t>& out) {
  nodes_ = 0;
  out.clear();
  if (depths.empty()) return;
  const std::uint64_t nodes = octree_node_count(depths);
  if (words.size() < nodes * node_slots * k::RESOCT_NODE_WORDS) {
    throw invalid_parameter("octree", std::to_string(words.size()) + " words for " +
                                          std::to_string(nodes) + " nodes of " +
                                          std::to_string(node_slots) + " slots");
  }
  const std::uint32_t entries =
      std::min<std::uint32_t>(std::uint32_t(slots.size()), k::RESOCT_MAX_SLOTS);
  shown_ = 0;
  for (std::uint32_t i = 0; i < entries; ++i) {
    if (slots[i].slot >= node_slots) {
      throw invalid_parameter("slots", "entry " + std::to_string(i) + " names slot " +
                                           std::to_string(slots[i].slot) + " of " +
                                           std::to_string(node_slots));
    }
    if (slots[i].vis_bins != 0u) shown_ |= 1u << i;
  }
  node_slots_ = node_slots;
  depths_.assign(depths.begin(), depths.end());
  slots_.assign(slots.begin(), slots.begin() + entries);
  extent_ = extent;
  start_depth_ = start_depth;
  depth_limit_ = std::min<std::uint32_t>(depth_limit, std::uint32_t(depths.size()) - 1);
  // Only a depth whose last nodes along an axis start past the volume has nodes outside it.
  some_outside_.assign(depths.size(), 0u);
  for (std::size_t d = 0; d < depths.size(); ++d) {
    const k::ResoctDepthInfo& D = depths[d];
    some_outside_[d] = std::uint64_t(D.count_x - 1u) * D.node_extent_x >= extent.x ||
                       std::uint64_t(D.count_y - 1u) * D.node_extent_y >= extent.y ||
                       std::uint64_t(D.count_z - 1u) * D.node_extent_z >= extent.z;
  }
  ok_.assign(std::size_t(nodes), 0u);
  out.assign(std::size_t(nodes), 0u);
  nodes_ = nodes;
  if (shown_ == 0u || depth_limit_ <= start_depth_) return;
  // Bottom-up from the depth limit, so that every node finds its children's masks.
  for (std::uint32_t d = depth_limit_ + 1; d-- > start_depth_;) {
    const k::ResoctDepthInfo& D = depths_[d];
    const std::uint32_t count = D.count_x * D.count_y * D.count_z;
    for (std::uint32_t local = 0; local < count; ++local) {
      const NodeResult r = compute(words, d, local);
      ok_[D.first_node + local] = r.ok;
      out[D.first_node + local] = r.bits;
    }
  }
}

VisibleSubtreeUpdate VisibleSubtreeBuilder::update(std::span<const std::uint32_t> words,
                                                   std::span<const std::uint32_t> nodes,
                                                   std::vector<std::uint32_t>& out) {
  if (nodes_ == 0 || out.size() != nodes_ ||
      words.size() < nodes_ * node_slots_ * k::RESOCT_NODE_WORDS) {
    throw invalid_parameter("octree", "update of visible subtrees without a build of this tree");
  }
  VisibleSubtreeUpdate result;
  if (shown_ == 0u || depth_limit_ <= start_depth_) return result;
  pending_.resize(depths_.size());
  for (std::vector<std::uint32_t>& p : pending_) p.clear();
  for (const std::uint32_t node : nodes) {
    if (node >= nodes_) {
      throw invalid_parameter("nodes",
                              "node " + std::to_string(node) + " of " + std::to_string(nodes_));
    }
    // The depth holding the node: the last one starting at or before it.
    std::uint32_t d = std::uint32_t(depths_.size()) - 1;
    while (depths_[d].first_node > node) --d;
    // Records below the limit are never read, and no node above the start depth has a word.
    if (d >= start_depth_ && d <= depth_limit_) pending_[d].push_back(node - depths_[d].first_node);
  }
  // Deepest first: a node is recomputed after its changed children, and its parent is queued
  // only when its mask changed (a word alone changing stops there).
  for (std::uint32_t d = depth_limit_ + 1; d-- > start_depth_;) {
    std::vector<std::uint32_t>& locals = pending_[d];
    std::sort(locals.begin(), locals.end());
    locals.erase(std::unique(locals.begin(), locals.end()), locals.end());
    const k::ResoctDepthInfo& D = depths_[d];
    for (const std::uint32_t local : locals) {
      const NodeResult r = compute(words, d, local);
      ++result.recomputed;
      if (out[D.first_node + local] != r.bits) {
        out[D.first_node + local] = r.bits;
        ++result.words_changed;
      }
      if (r.ok != ok_[D.first_node + local]) {
        ok_[D.first_node + local] = r.ok;
        if (d > start_depth_) pending_[d - 1].push_back(local >> D.child_shift);
      }
    }
  }
  return result;
}

void VisibleSubtreeBuilder::build(const ResidencyOctree& octree, FrameTables& tables,
                                  std::uint32_t depth_limit) {
  build(octree.words(), tables.frame.node_slot_count, tables.depths, tables.slots,
        glm::uvec3(tables.frame.extent_x, tables.frame.extent_y, tables.frame.extent_z),
        tables.frame.start_depth, depth_limit, tables.visible_subtrees);
  tables.visible_subtrees_version = next_visible_subtrees_version();
}

VisibleSubtreeUpdate VisibleSubtreeBuilder::update(const ResidencyOctree& octree,
                                                   std::span<const std::uint32_t> nodes,
                                                   FrameTables& tables) {
  const VisibleSubtreeUpdate result = update(octree.words(), nodes, tables.visible_subtrees);
  if (result.words_changed != 0) tables.visible_subtrees_version = next_visible_subtrees_version();
  return result;
}

}  // namespace resoct
