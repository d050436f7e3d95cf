#pragma once
/// \file
/// Spatial subdivision of the residency octree: a full, pointerless tree over the level-0 voxels,
/// independent of the brick hierarchy. See docs/residency-octree.md.

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/box.hpp"

namespace resoct {

/// One subdivision depth of an OctreeLayout. Depth 0 is the root.
struct OctreeDepth {
  glm::uvec3 count_log2{0};      ///< nodes per axis = 1 << count_log2
  glm::uvec3 count{1};           ///< nodes per axis
  glm::uvec3 split{0};           ///< 1 on the axes halved from the previous depth (0 at the root)
  std::uint32_t child_shift{0};  ///< log2 of the children per node of the previous depth
  glm::u64vec3 node_extent{1};   ///< level-0 voxels per node and axis (before clamping)
  std::uint64_t first_node{0};   ///< flat index of this depth's first node
  std::uint64_t node_count{1};   ///< nodes at this depth
};

/// Half-open range of node coordinates at one depth.
struct NodeCoordRange {
  glm::uvec3 lo{0};
  glm::uvec3 hi{0};
  bool empty() const noexcept { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
  std::uint64_t size() const noexcept {
    return empty() ? 0u : std::uint64_t(hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
  }
};

/// Subdivision of a level-0 extent into a full tree whose leaves are at most `leaf_size` voxels
/// per axis.
///
/// Geometry: per axis i the tree halves K_i times, K_i = ceil(log2(ceil(E_i / leaf_i))), so the
/// root covers the *padded* extent leaf_i << K_i and a node at depth d covers exactly
/// [c * n_i, (c + 1) * n_i) with n_i = leaf_i << (K_i - splits so far). Node boxes are clamped to
/// the volume; nodes past the far border are empty boxes (they exist in the flat array but no
/// voxel maps to them). Every level-0 voxel lies in exactly one node per depth, boxes nest
/// exactly, and when leaf and brick sizes are powers of two the node borders align with brick
/// borders (a 32³ brick covers exactly 2³ leaves of 16³), which keeps updates cheap.
///
/// Split order (thesis §8.4.1): at each step only the axes with the most remaining halvings split,
/// i.e. an axis splits only while its node extent in leaf units is not smaller than half of the
/// largest. Leaf units (not voxels) make an anisotropic leaf such as 8×8×4 behave like a cube.
///
/// Node order: the children of a node are contiguous. A node's index within its depth is the
/// parent's index times the children per node plus the child's bits (z, y, x of the split axes,
/// x least significant): a generalized Morton order. Flat index = first_node(depth) + local.
///
/// Immutable after construction; all members are safe to call concurrently.
class OctreeLayout {
 public:
  /// Largest number of nodes a layout may have, so that device-side node indices fit 32 bits.
  static constexpr std::uint64_t kMaxNodes = std::uint64_t(1) << 31;
  /// Returned by parent() for the root.
  static constexpr std::uint64_t kNoNode = ~std::uint64_t(0);

  OctreeLayout() : OctreeLayout(glm::u64vec3(1), glm::uvec3(1)) {}
  /// Throws Error(invalid_argument) naming "leaf_size" when an axis is 0 or above 2^20, naming
  /// "extent" when an axis is 0 or above 2^40, and naming "leaf_size" when the tree would have
  /// more than kMaxNodes nodes (e.g. leaf 1³ on 65536³).
  OctreeLayout(glm::u64vec3 extent0, glm::uvec3 leaf_size);

  glm::u64vec3 extent0() const noexcept { return extent0_; }
  glm::uvec3 leaf_size() const noexcept { return leaf_size_; }
  std::uint32_t depth_count() const noexcept { return std::uint32_t(depths_.size()); }
  std::uint32_t leaf_depth() const noexcept { return depth_count() - 1u; }
  const OctreeDepth& depth(std::uint32_t d) const { return depths_.at(d); }
  const std::vector<OctreeDepth>& depths() const noexcept { return depths_; }
  std::uint64_t node_count() const noexcept { return node_count_; }
  std::uint64_t leaf_count() const noexcept { return depths_.back().node_count; }

  /// Depth of a flat node index (throws Error(out_of_range) past the last node).
  std::uint32_t depth_of(std::uint64_t node) const;
  /// Flat index of the node with coordinates c at depth d (c must be < count).
  std::uint64_t node_index(std::uint32_t d, const glm::uvec3& c) const;
  /// Coordinates of a node within its depth.
  glm::uvec3 node_coord(std::uint64_t node) const;
  /// Level-0 voxels of a node, clamped to the volume (empty for nodes past the far border).
  Box3 node_box(std::uint64_t node) const;
  Box3 node_box(std::uint32_t d, const glm::uvec3& c) const;

  /// The level-0 voxels whose values a level-0 trilinear sample inside the node can read: the
  /// node box grown by one voxel per side, clamped to the volume. Node metadata must be queried
  /// over this box, or culling and the homogeneous shortcut disagree with sampling near faces.
  Box3 sampling_support(std::uint64_t node) const;

  /// Parent of a node, kNoNode for the root.
  std::uint64_t parent(std::uint64_t node) const;
  /// First child and child count of a node; count 0 for leaves.
  struct Children {
    std::uint64_t first = 0;
    std::uint32_t count = 0;
  };
  Children children(std::uint64_t node) const;

  /// Nodes at depth d whose (clamped) boxes overlap a level-0 box.
  NodeCoordRange node_range(std::uint32_t d, const Box3& level0) const;
  /// Leaves overlapping a level-0 box.
  NodeCoordRange leaf_range(const Box3& level0) const { return node_range(leaf_depth(), level0); }

  /// The nodes at depth d - 1 containing the nodes of range r at depth d (their parents). Since
  /// boxes nest exactly, parent_range(d, node_range(d, box)) == node_range(d - 1, box).
  NodeCoordRange parent_range(std::uint32_t d, const NodeCoordRange& r) const noexcept {
    const glm::uvec3 split = depths_[d].split;
    return NodeCoordRange{r.lo >> split, ((r.hi - 1u) >> split) + 1u};
  }

  /// The bits coordinate c of `axis` contributes to a local (within-depth) node index at depth d;
  /// the local index is the OR over the three axes.
  std::uint64_t local_bits(std::uint32_t d, int axis, std::uint32_t c) const noexcept {
    const auto& pos = bit_pos_[d][std::size_t(axis)];
    std::uint64_t out = 0;
    for (std::uint32_t k = 0; c != 0; ++k, c >>= 1) out |= std::uint64_t(c & 1u) << pos[k];
    return out;
  }

  /// Calls fn(flat_index, coord) for every node of a coordinate range at depth d, x fastest.
  template <class Fn>
  void for_each_node(std::uint32_t d, const NodeCoordRange& r, Fn&& fn) const {
    if (r.empty()) return;
    const std::uint64_t first = depths_[d].first_node;
    const std::array<std::uint64_t, 3>& m = axis_mask_[d];
    // Stepping a coordinate by one inside its interleaved bits: fill the other axes' bits with
    // ones so that the carry skips them (the usual Morton-order increment).
    auto step = [](std::uint64_t bits, std::uint64_t mask) { return ((bits | ~mask) + 1u) & mask; };
    const std::uint64_t x0 = local_bits(d, 0, r.lo.x);
    std::uint64_t zb = local_bits(d, 2, r.lo.z);
    for (std::uint32_t z = r.lo.z; z < r.hi.z; ++z, zb = step(zb, m[2])) {
      std::uint64_t yb = local_bits(d, 1, r.lo.y);
      for (std::uint32_t y = r.lo.y; y < r.hi.y; ++y, yb = step(yb, m[1])) {
        std::uint64_t xb = x0;
        for (std::uint32_t x = r.lo.x; x < r.hi.x; ++x, xb = step(xb, m[0])) {
          fn(first + (zb | yb | xb), glm::uvec3(x, y, z));
        }
      }
    }
  }

 private:
  glm::u64vec3 extent0_{1};
  glm::uvec3 leaf_size_{1};
  std::vector<OctreeDepth> depths_;
  // bit_pos_[d][axis][k]: position in the local index at depth d of coordinate bit k.
  std::vector<std::array<std::array<std::uint8_t, 32>, 3>> bit_pos_;
  // axis_mask_[d][axis]: all local-index bits that belong to that axis at depth d.
  std::vector<std::array<std::uint64_t, 3>> axis_mask_;
  std::uint64_t node_count_ = 0;
};

}  // namespace resoct
