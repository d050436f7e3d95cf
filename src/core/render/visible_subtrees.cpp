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
  out.clear();
  if (depths.empty()) return;
  const k::ResoctDepthInfo& last = depths.back();
  const std::uint64_t nodes =
      std::uint64_t(last.first_node) + std::uint64_t(last.count_x) * last.count_y * last.count_z;
  if (words.size() < nodes * node_slots * k::RESOCT_NODE_WORDS) {
    throw invalid_parameter("octree", std::to_string(words.size()) + " words for " +
                                          std::to_string(nodes) + " nodes of " +
                                          std::to_string(node_slots) + " slots");
  }
  const std::uint32_t entries =
      std::min<std::uint32_t>(std::uint32_t(slots.size()), k::RESOCT_MAX_SLOTS);
  std::uint32_t shown = 0;  // entries whose transfer function shows anything
  for (std::uint32_t i = 0; i < entries; ++i) {
    if (slots[i].slot >= node_slots) {
      throw invalid_parameter("slots", "entry " + std::to_string(i) + " names slot " +
                                           std::to_string(slots[i].slot) + " of " +
                                           std::to_string(node_slots));
    }
    if (slots[i].vis_bins != 0u) shown |= 1u << i;
  }
  out.assign(std::size_t(nodes), 0u);
  depth_limit = std::min<std::uint32_t>(depth_limit, std::uint32_t(depths.size()) - 1);
  if (shown == 0u || depth_limit <= start_depth) return;

  // Bottom-up from the depth limit: `ok` holds, per node of the depth below, the entries for
  // which that node and its subtree (down to the limit) have metadata and are shown; a node's bit
  // additionally needs a record that is not homogeneous. The limit's own nodes are checked but
  // their children are not: no ray descends past them.
  std::vector<std::uint32_t> ok_below;
  std::vector<std::uint32_t> ok_here;
  for (std::uint32_t d = depth_limit + 1; d-- > start_depth;) {
    const k::ResoctDepthInfo& D = depths[d];
    const std::uint32_t count = D.count_x * D.count_y * D.count_z;
    const std::uint32_t child_shift = d < depth_limit ? depths[d + 1].child_shift : 0u;
    ok_here.assign(count, 0u);
    // Only a depth whose last nodes along an axis start past the volume has nodes outside it.
    const bool some_outside = std::uint64_t(D.count_x - 1u) * D.node_extent_x >= extent.x ||
                              std::uint64_t(D.count_y - 1u) * D.node_extent_y >= extent.y ||
                              std::uint64_t(D.count_z - 1u) * D.node_extent_z >= extent.z;
    for (std::uint32_t local = 0; local < count; ++local) {
      if (some_outside && outside_volume(D, local, extent)) {
        ok_here[local] = shown;
        continue;
      }
      std::uint32_t ok = shown;
      if (d < depth_limit) {
        const std::uint32_t first = local << child_shift;
        for (std::uint32_t c = 0; c < (1u << child_shift); ++c) ok &= ok_below[first + c];
      }
      std::uint32_t bits = 0;
      for (std::uint32_t pending = ok; pending != 0u; pending &= pending - 1u) {
        const std::uint32_t i = std::uint32_t(std::countr_zero(pending));
        bool homogeneous = false;
        if (!record_shown(words, D.first_node + local, slots[i], node_slots, homogeneous)) {
          ok &= ~(1u << i);
        } else if (!homogeneous) {
          bits |= 1u << i;
        }
      }
      ok_here[local] = ok;
      if (d < depth_limit) out[D.first_node + local] = bits;
    }
    std::swap(ok_below, ok_here);
  }
}

void build_visible_subtrees(const ResidencyOctree& octree, FrameTables& tables) {
  if (tables.frame.mode != k::RESOCT_MODE_RESIDENCY) {
    tables.visible_subtrees.clear();
    tables.visible_subtrees_version = 0;
    return;
  }
  build_visible_subtrees(
      octree.words(), tables.frame.node_slot_count, tables.depths, tables.slots,
      glm::uvec3(tables.frame.extent_x, tables.frame.extent_y, tables.frame.extent_z),
      tables.frame.start_depth,
      deepest_traversal_depth(tables.frame, tables.levels, tables.depths, tables.slots),
      tables.visible_subtrees);
  // A process-wide counter: two producers never hand one backend equal versions of different bits.
  static std::atomic<std::uint64_t> next_version{1};
  tables.visible_subtrees_version = next_version.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace resoct
