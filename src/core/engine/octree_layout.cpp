#include "resoct/engine/octree_layout.hpp"

#include <algorithm>
#include <bit>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {
constexpr std::uint64_t kMaxLeaf = std::uint64_t(1) << 20;
constexpr std::uint64_t kMaxExtent = std::uint64_t(1) << 40;

std::uint32_t ceil_log2(std::uint64_t v) {
  return v <= 1 ? 0u : std::uint32_t(std::bit_width(v - 1));
}
}  // namespace

OctreeLayout::OctreeLayout(glm::u64vec3 extent0, glm::uvec3 leaf_size)
    : extent0_(extent0), leaf_size_(leaf_size) {
  glm::uvec3 halvings{0};
  for (int i = 0; i < 3; ++i) {
    if (leaf_size[i] == 0 || leaf_size[i] > kMaxLeaf) {
      throw invalid_parameter("leaf_size", "each axis must be 1.." + std::to_string(kMaxLeaf) +
                                               " voxels, got " + std::to_string(leaf_size[i]));
    }
    if (extent0[i] == 0 || extent0[i] > kMaxExtent) {
      throw invalid_parameter(
          "extent", "each axis must be 1..2^40 voxels, got " + std::to_string(extent0[i]));
    }
    const std::uint64_t leaves = (extent0[i] + leaf_size[i] - 1) / leaf_size[i];
    halvings[i] = ceil_log2(leaves);
  }

  // Count nodes before allocating anything so that absurd parameters fail fast.
  {
    glm::uvec3 remaining = halvings;
    glm::uvec3 have{0};
    std::uint64_t total = 1;
    while (remaining.x + remaining.y + remaining.z > 0) {
      const std::uint32_t most = std::max({remaining.x, remaining.y, remaining.z});
      for (int i = 0; i < 3; ++i) {
        if (remaining[i] == most) {
          --remaining[i];
          ++have[i];
        }
      }
      total += std::uint64_t(1) << (have.x + have.y + have.z);
      if (total > kMaxNodes) {
        throw Error(ErrorCode::invalid_argument,
                    "parameter 'leaf_size': leaves of " + std::to_string(leaf_size.x) + "x" +
                        std::to_string(leaf_size.y) + "x" + std::to_string(leaf_size.z) + " on a " +
                        std::to_string(extent0.x) + "x" + std::to_string(extent0.y) + "x" +
                        std::to_string(extent0.z) + " volume need more than 2^31 " +
                        "octree nodes; use larger leaves");
      }
    }
  }

  glm::uvec3 remaining = halvings;
  OctreeDepth d;
  for (int i = 0; i < 3; ++i) d.node_extent[i] = std::uint64_t(leaf_size[i]) << halvings[i];
  depths_.push_back(d);
  node_count_ = 1;
  while (remaining.x + remaining.y + remaining.z > 0) {
    const std::uint32_t most = std::max({remaining.x, remaining.y, remaining.z});
    OctreeDepth next = depths_.back();
    next.child_shift = 0;
    for (int i = 0; i < 3; ++i) {
      next.split[i] = remaining[i] == most ? 1u : 0u;
      remaining[i] -= next.split[i];
      next.count_log2[i] += next.split[i];
      next.count[i] = 1u << next.count_log2[i];
      next.node_extent[i] >>= next.split[i];
      next.child_shift += next.split[i];
    }
    next.first_node = node_count_;
    next.node_count = std::uint64_t(1)
                      << (next.count_log2.x + next.count_log2.y + next.count_log2.z);
    node_count_ += next.node_count;
    depths_.push_back(next);
  }

  // Step j's offset occupies the bits above those of steps j+1..d, x lowest within a step.
  bit_pos_.resize(depths_.size());
  for (std::size_t dd = 0; dd < depths_.size(); ++dd) {
    auto& pos = bit_pos_[dd];
    for (auto& a : pos) a.fill(0);
    std::uint32_t below = 0;
    for (std::size_t j = dd; j >= 1; --j) {
      std::uint32_t bit = below;
      for (int i = 0; i < 3; ++i) {
        if (depths_[j].split[i] == 0) continue;
        const std::uint32_t k = depths_[dd].count_log2[i] - depths_[j].count_log2[i];
        pos[std::size_t(i)][k] = std::uint8_t(bit++);
      }
      below += depths_[j].child_shift;
    }
  }
  axis_mask_.resize(depths_.size());
  for (std::uint32_t dd = 0; dd < depth_count(); ++dd) {
    for (int i = 0; i < 3; ++i) {
      axis_mask_[dd][std::size_t(i)] = local_bits(dd, i, depths_[dd].count[i] - 1u);
    }
  }
}

std::uint32_t OctreeLayout::depth_of(std::uint64_t node) const {
  if (node >= node_count_) {
    throw Error(ErrorCode::out_of_range, "octree node " + std::to_string(node) + " past the " +
                                             std::to_string(node_count_) + " nodes");
  }
  // Depths hold 2^k nodes with k growing, so a scan from the leaves ends after a few steps.
  std::uint32_t d = leaf_depth();
  while (depths_[d].first_node > node) --d;
  return d;
}

std::uint64_t OctreeLayout::node_index(std::uint32_t d, const glm::uvec3& c) const {
  const OctreeDepth& target = depths_.at(d);
  return target.first_node +
         (local_bits(d, 0, c.x) | local_bits(d, 1, c.y) | local_bits(d, 2, c.z));
}

glm::uvec3 OctreeLayout::node_coord(std::uint64_t node) const {
  const std::uint32_t d = depth_of(node);
  const OctreeDepth& target = depths_[d];
  std::uint64_t local = node - target.first_node;
  glm::uvec3 c{0};
  for (std::uint32_t j = d; j >= 1; --j) {
    const OctreeDepth& step = depths_[j];
    std::uint64_t offset = local & ((std::uint64_t(1) << step.child_shift) - 1u);
    local >>= step.child_shift;
    for (int i = 0; i < 3; ++i) {
      if (step.split[i] == 0) continue;
      const std::uint32_t shift = target.count_log2[i] - step.count_log2[i];
      c[i] |= std::uint32_t(offset & 1u) << shift;
      offset >>= 1;
    }
  }
  return c;
}

Box3 OctreeLayout::node_box(std::uint32_t d, const glm::uvec3& c) const {
  const OctreeDepth& dep = depths_.at(d);
  Box3 b;
  for (int i = 0; i < 3; ++i) {
    const std::int64_t e = std::int64_t(extent0_[i]);
    const std::int64_t n = std::int64_t(dep.node_extent[i]);
    b.lo[i] = std::min(std::int64_t(c[i]) * n, e);
    b.hi[i] = std::min((std::int64_t(c[i]) + 1) * n, e);
  }
  return b;
}

Box3 OctreeLayout::node_box(std::uint64_t node) const {
  return node_box(depth_of(node), node_coord(node));
}

std::uint64_t OctreeLayout::parent(std::uint64_t node) const {
  const std::uint32_t d = depth_of(node);
  if (d == 0) return kNoNode;
  const std::uint64_t local = node - depths_[d].first_node;
  return depths_[d - 1].first_node + (local >> depths_[d].child_shift);
}

OctreeLayout::Children OctreeLayout::children(std::uint64_t node) const {
  const std::uint32_t d = depth_of(node);
  if (d == leaf_depth()) return {};
  const OctreeDepth& next = depths_[d + 1];
  const std::uint64_t local = node - depths_[d].first_node;
  return {next.first_node + (local << next.child_shift), 1u << next.child_shift};
}

NodeCoordRange OctreeLayout::node_range(std::uint32_t d, const Box3& level0) const {
  const OctreeDepth& dep = depths_.at(d);
  NodeCoordRange r;
  for (int i = 0; i < 3; ++i) {
    const std::int64_t e = std::int64_t(extent0_[i]);
    const std::int64_t lo = std::clamp<std::int64_t>(level0.lo[i], 0, e);
    const std::int64_t hi = std::clamp<std::int64_t>(level0.hi[i], 0, e);
    if (hi <= lo) return NodeCoordRange{};
    const std::uint64_t n = dep.node_extent[i];
    if (std::has_single_bit(n)) {  // the common power-of-two leaf: no 64-bit division
      const int s = std::countr_zero(n);
      r.lo[i] = std::uint32_t(std::uint64_t(lo) >> s);
      r.hi[i] = std::uint32_t((std::uint64_t(hi) + n - 1) >> s);
    } else {
      r.lo[i] = std::uint32_t(std::uint64_t(lo) / n);
      r.hi[i] = std::uint32_t((std::uint64_t(hi) + n - 1) / n);
    }
  }
  return r;
}

Box3 OctreeLayout::sampling_support(std::uint64_t node) const {
  Box3 box = node_box(node);
  if (box.empty()) return box;
  box.lo = glm::max(box.lo - glm::i64vec3(1), glm::i64vec3(0));
  box.hi = glm::min(box.hi + glm::i64vec3(1), glm::i64vec3(extent0_));
  return box;
}

}  // namespace resoct
