// Residency octree culling metadata: the per-record rule, upward propagation and the two ways
// metadata arrives (region queries and, as a fallback, brick voxels).
#include <algorithm>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/engine/leaf_scan.hpp"
#include "resoct/engine/residency_octree.hpp"

namespace resoct {

namespace k = resoct::kernel;

namespace {

// The intersection of two min/max words that both bound the same values (0: no values).
std::uint32_t intersect_minmax(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t r =
      (std::min(a >> 16u, b >> 16u) << 16u) | std::min(a & 0xffffu, b & 0xffffu);
  return k::resoct_node_range_empty(r) ? 0u : r;
}

}  // namespace

ResidencyOctree::Record ResidencyOctree::compute_record(
    std::uint32_t d, std::uint64_t node, glm::uvec3 coord, std::uint32_t slot,
    std::span<const std::uint32_t> storage) const {
  Record r;
  const auto it = own_.find(node * slots_ + slot);
  const OwnMeta* own = it == own_.end() ? nullptr : &it->second;
  const bool own_conservative = own != nullptr && (own->has_direct || own->has_exact);
  if (own != nullptr && own->has_direct && own->has_exact) {
    // Both bound the values of the node's sampling support, so their intersection does too: a
    // region answer from a source's metadata blocks is often much wider than the scan of a
    // level-0 brick (a 16³ block grid answers for 48³ voxels around a 16³ leaf).
    r.minmax = intersect_minmax(own->direct_minmax, own->exact_minmax);
    r.occupancy = own->direct_occupancy & own->exact_occupancy;
  } else if (own != nullptr && own->has_direct) {
    r.minmax = k::resoct_node_merge_minmax(r.minmax, own->direct_minmax);
    r.occupancy |= own->direct_occupancy;
  } else if (own != nullptr && own->has_exact) {
    r.minmax = k::resoct_node_merge_minmax(r.minmax, own->exact_minmax);
    r.occupancy |= own->exact_occupancy;
  }

  // Children always contribute their values, whatever their state, so that a parent is never
  // narrower than a child; only their states decide whether the union is complete.
  Record children;
  std::uint32_t non_empty = 0;
  bool all_valid = true;
  bool all_known = true;
  std::uint32_t child_level = 0;
  if (d < layout_.leaf_depth()) {
    const OctreeDepth& here = layout_.depth(d);
    const OctreeDepth& next = layout_.depth(d + 1);
    const std::uint64_t first = next.first_node + ((node - here.first_node) << next.child_shift);
    const glm::u64vec3 extent = layout_.extent0();
    for (std::uint32_t kid = 0; kid < (1u << next.child_shift); ++kid) {
      std::uint32_t bits = kid;
      bool empty = false;
      for (int i = 0; i < 3; ++i) {
        std::uint64_t c = coord[i];
        if (next.split[i] != 0) {
          c = 2 * c + (bits & 1u);
          bits >>= 1;
        }
        empty = empty || c * next.node_extent[i] >= extent[i];
      }
      if (empty) continue;
      ++non_empty;
      const std::size_t b = base(first + kid, slot);
      children.minmax =
          k::resoct_node_merge_minmax(children.minmax, storage[b + k::RESOCT_NODE_MINMAX]);
      children.occupancy |= storage[b + k::RESOCT_NODE_OCCUPANCY];
      const std::uint32_t flags = storage[b + k::RESOCT_NODE_FLAGS];
      const std::uint32_t st = k::resoct_node_state(flags);
      all_valid = all_valid && st == k::RESOCT_NODE_VALID;
      all_known = all_known && st != k::RESOCT_NODE_INVALID;
      if (st == k::RESOCT_NODE_APPROX) {
        child_level = std::max(child_level, k::resoct_node_approx_level(flags));
      }
    }
  }
  all_valid = all_valid && non_empty > 0;
  all_known = all_known && non_empty > 0;
  if (all_valid) {
    // The children's supports cover the node's, so their union alone bounds its values; the
    // node's own answer could only widen it (a source answers a large region from coarse
    // metadata blocks, while the leaves below may hold exact scans of their bricks).
    r.minmax = children.minmax;
    r.occupancy = children.occupancy;
  } else {
    r.minmax = k::resoct_node_merge_minmax(r.minmax, children.minmax);
    r.occupancy |= children.occupancy;
  }

  if (own_conservative || all_valid) {
    r.flags = k::resoct_node_make_flags(k::RESOCT_NODE_VALID, 0u);
  } else if (own != nullptr && own->has_approx) {
    r.minmax = k::resoct_node_merge_minmax(r.minmax, own->approx_minmax);
    r.occupancy |= own->approx_occupancy;
    r.flags = k::resoct_node_make_flags(k::RESOCT_NODE_APPROX, own->approx_level);
  } else if (all_known) {
    r.flags = k::resoct_node_make_flags(k::RESOCT_NODE_APPROX, child_level);
  }
  return r;
}

void ResidencyOctree::propagate_metadata(std::uint32_t slot, std::uint32_t d,
                                         NodeCoordRange range) {
  for (;;) {
    bool changed = false;
    layout_.for_each_node(d, range, [&](std::uint64_t node, glm::uvec3 c) {
      ++stats_.nodes_visited;
      const Record r = compute_record(d, node, c, slot, words_);
      const std::size_t b = base(node, slot);
      const Record old{words_[b + k::RESOCT_NODE_MINMAX], words_[b + k::RESOCT_NODE_OCCUPANCY],
                       words_[b + k::RESOCT_NODE_FLAGS]};
      if (r == old) return;
      set_word(b + k::RESOCT_NODE_MINMAX, r.minmax);
      set_word(b + k::RESOCT_NODE_OCCUPANCY, r.occupancy);
      set_word(b + k::RESOCT_NODE_FLAGS, r.flags);
      changed = true;
    });
    if (!changed || d == 0) return;
    range = layout_.parent_range(d, range);
    --d;
  }
}

void ResidencyOctree::node_metadata(std::uint32_t slot, std::uint64_t node,
                                    const RegionMeta& meta) {
  check_slot(slot);
  const std::uint32_t d = layout_.depth_of(node);  // throws past the last node
  const glm::uvec3 c = layout_.node_coord(node);
  if (layout_.node_box(d, c).empty()) {
    throw Error(ErrorCode::out_of_range,
                "octree node " + std::to_string(node) + " lies outside the volume");
  }
  OwnMeta& o = own(node, slot);
  o.has_direct = true;
  o.direct_minmax = octree_pack_range(meta.min, meta.max, ranges_[slot]);
  o.direct_occupancy = meta.occupancy;
  o.has_approx = false;  // conservative data replaces any estimate
  propagate_metadata(slot, d, NodeCoordRange{c, c + 1u});
}

void ResidencyOctree::leaf_metadata(std::uint32_t slot, glm::uvec3 brick,
                                    std::span<const LeafScan> leaves) {
  check_slot(slot);
  check_brick(0, brick);
  // Only the leaves whose records this brick can give (scan_leaves' rule, for_each_exact_leaf):
  // a leaf that merely overlaps the brick, or whose sampling support the padded brick does not
  // hold, would get a record of voxels it does not cover.
  std::vector<std::uint64_t> exact;
  for_each_exact_leaf(layout_, hierarchy_, brick,
                      [&exact](std::uint64_t leaf, const Box3&) { exact.push_back(leaf); });
  std::sort(exact.begin(), exact.end());
  for (const LeafScan& l : leaves) {
    if (!std::binary_search(exact.begin(), exact.end(), l.leaf)) {
      throw Error(ErrorCode::out_of_range,
                  "leaf " + std::to_string(l.leaf) + " is not a leaf of level-0 brick (" +
                      std::to_string(brick.x) + ", " + std::to_string(brick.y) + ", " +
                      std::to_string(brick.z) + ") whose sampling support the brick holds");
    }
  }
  for (const LeafScan& l : leaves) {
    OwnMeta& o = own(l.leaf, slot);
    o.has_exact = true;
    o.exact_minmax = l.minmax;
    o.exact_occupancy = l.occupancy;
    o.has_approx = false;
  }
  const std::uint32_t d = layout_.leaf_depth();
  const NodeCoordRange range = layout_.node_range(d, hierarchy_.level0_box(0, brick));
  if (!range.empty()) propagate_metadata(slot, d, range);
}

void ResidencyOctree::metadata_from_constant_brick(std::uint32_t slot, glm::uvec3 brick,
                                                   const BrickMeta& meta) {
  check_slot(slot);
  leaf_metadata(slot, brick, scan_constant_leaves(layout_, hierarchy_, ranges_[slot], brick, meta));
}

void ResidencyOctree::metadata_from_brick(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick,
                                          std::span<const std::byte> voxels) {
  check_slot(slot);
  check_brick(level, brick);
  if (level == 0) {
    leaf_metadata(slot, brick, scan_leaves(layout_, hierarchy_, ranges_[slot], brick, voxels));
    return;
  }
  const VoxelType type = hierarchy_.volume().type;
  const std::uint64_t expected = hierarchy_.layout().padded_voxels() * voxel_size(type);
  if (voxels.size() != expected) {
    throw invalid_parameter("voxels", "brick buffer has " + std::to_string(voxels.size()) +
                                          " bytes, expected " + std::to_string(expected));
  }
  const Box3 box0 = hierarchy_.level0_box(level, brick);
  const Box3 core = hierarchy_.core_box(level, brick);
  const glm::i64vec3 padded_lo = core.lo - glm::i64vec3(hierarchy_.layout().halo);
  const glm::i64vec3 padded_dim(hierarchy_.layout().padded_size());
  const glm::uvec3 f = hierarchy_.level(level).factor_log2;

  // Nodes finer than one level-l voxel would only repeat that voxel's value: stop at the deepest
  // depth whose nodes still span a whole voxel.
  std::uint32_t d = 0;
  for (std::uint32_t t = 0; t <= layout_.leaf_depth(); ++t) {
    bool fits = true;
    for (int i = 0; i < 3; ++i) {
      const std::uint64_t need =
          std::min(std::uint64_t(1) << f[i], layout_.depth(0).node_extent[i]);
      fits = fits && layout_.depth(t).node_extent[i] >= need;
    }
    if (fits) d = t;
  }

  const NodeCoordRange range = layout_.node_range(d, box0);
  const ValueRange& vr = ranges_[slot];
  layout_.for_each_node(d, range, [&](std::uint64_t node, glm::uvec3 c) {
    const Box3 nb = layout_.node_box(d, c);
    if (nb.empty() || intersect(nb, box0) != nb) return;  // only nodes the brick fully covers
    const auto it = own_.find(node * slots_ + slot);
    const OwnMeta* had = it == own_.end() ? nullptr : &it->second;
    if (had != nullptr &&
        (had->has_direct || had->has_exact || (had->has_approx && had->approx_level < level))) {
      return;  // an estimate never replaces conservative data or a finer estimate
    }
    const VoxelBoxScan s =
        scan_voxel_box(voxels, type, padded_lo, padded_dim,
                       intersect(hierarchy_.level_box_from_level0(level, nb), core), vr);
    OwnMeta& o = own(node, slot);
    o.has_approx = true;
    o.approx_minmax = octree_pack_range(s.min, s.max, vr);
    o.approx_occupancy = s.occupancy;
    o.approx_level = level;
  });
  if (!range.empty()) propagate_metadata(slot, d, range);
}

}  // namespace resoct
