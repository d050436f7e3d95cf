#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/engine/octree_layout.hpp"
#include "support/expect_error.hpp"

namespace resoct {
namespace {

// Every level-0 voxel lies in exactly one node box per depth (small volumes only).
void expect_voxel_tiling(const OctreeLayout& layout) {
  const glm::u64vec3 e = layout.extent0();
  for (std::uint32_t d = 0; d < layout.depth_count(); ++d) {
    std::vector<std::uint8_t> hits(std::size_t(e.x * e.y * e.z), 0);
    const OctreeDepth& dep = layout.depth(d);
    for (std::uint64_t n = dep.first_node; n < dep.first_node + dep.node_count; ++n) {
      const Box3 b = layout.node_box(n);
      for (std::int64_t z = b.lo.z; z < b.hi.z; ++z)
        for (std::int64_t y = b.lo.y; y < b.hi.y; ++y)
          for (std::int64_t x = b.lo.x; x < b.hi.x; ++x) {
            ASSERT_TRUE(x >= 0 && y >= 0 && z >= 0);
            ASSERT_TRUE(std::uint64_t(x) < e.x && std::uint64_t(y) < e.y && std::uint64_t(z) < e.z);
            ++hits[std::size_t(x + std::int64_t(e.x) * (y + std::int64_t(e.y) * z))];
          }
    }
    for (std::size_t i = 0; i < hits.size(); ++i) {
      ASSERT_EQ(hits[i], 1) << "depth " << d << " voxel " << i;
    }
  }
}

// Large volumes: node boxes are products of per-axis intervals, so check that at every depth the
// intervals of each axis tile [0, E) in order without gaps or overlaps.
void expect_axis_tiling(const OctreeLayout& layout) {
  const glm::u64vec3 e = layout.extent0();
  for (std::uint32_t d = 0; d < layout.depth_count(); ++d) {
    const OctreeDepth& dep = layout.depth(d);
    for (int a = 0; a < 3; ++a) {
      std::int64_t covered = 0;
      for (std::uint32_t c = 0; c < dep.count[a]; ++c) {
        glm::uvec3 coord(0);
        coord[a] = c;
        const Box3 b = layout.node_box(d, coord);
        if (b.hi[a] == b.lo[a]) {  // empty padding node: only past the volume
          ASSERT_EQ(std::uint64_t(b.lo[a]), e[a]);
          continue;
        }
        ASSERT_EQ(b.lo[a], covered) << "depth " << d << " axis " << a << " node " << c;
        covered = b.hi[a];
      }
      ASSERT_EQ(std::uint64_t(covered), e[a]) << "depth " << d << " axis " << a;
    }
  }
}

void expect_tree_consistent(const OctreeLayout& layout) {
  ASSERT_EQ(layout.parent(0), OctreeLayout::kNoNode);
  std::uint64_t total = 0;
  for (std::uint32_t d = 0; d < layout.depth_count(); ++d) total += layout.depth(d).node_count;
  ASSERT_EQ(total, layout.node_count());
  for (std::uint64_t n = 0; n < layout.node_count(); ++n) {
    const std::uint32_t d = layout.depth_of(n);
    const glm::uvec3 c = layout.node_coord(n);
    ASSERT_EQ(layout.node_index(d, c), n);
    const Box3 box = layout.node_box(n);
    const OctreeLayout::Children ch = layout.children(n);
    if (d == layout.leaf_depth()) {
      ASSERT_EQ(ch.count, 0u);
      for (int a = 0; a < 3; ++a) ASSERT_LE(box.size()[a], std::int64_t(layout.leaf_size()[a]));
      continue;
    }
    ASSERT_EQ(ch.count, 1u << layout.depth(d + 1).child_shift);
    std::int64_t child_volume = 0;
    for (std::uint32_t i = 0; i < ch.count; ++i) {
      ASSERT_EQ(layout.parent(ch.first + i), n);
      const Box3 cb = layout.node_box(ch.first + i);
      if (!cb.empty()) {
        ASSERT_EQ(intersect(cb, box), cb);
      }
      child_volume += cb.volume();
    }
    ASSERT_EQ(child_volume, box.volume());
  }
}

TEST(OctreeLayout, TilesAwkwardSmallExtentsExactly) {
  const std::vector<std::pair<glm::u64vec3, glm::uvec3>> cases = {
      {{1, 1, 1}, {1, 1, 1}},       {{31, 1, 1}, {4, 4, 4}},  {{33, 33, 33}, {8, 8, 8}},
      {{40, 40, 40}, {16, 16, 16}}, {{40, 7, 33}, {8, 8, 4}}, {{3, 5, 2}, {1, 1, 1}},
      {{795, 3, 1}, {16, 16, 16}},  {{64, 64, 1}, {8, 8, 8}}, {{17, 9, 40}, {3, 5, 7}},
      {{40, 795, 33}, {4, 16, 8}},
  };
  for (const auto& [extent, leaf] : cases) {
    SCOPED_TRACE(testing::Message() << extent.x << "x" << extent.y << "x" << extent.z);
    const OctreeLayout layout(extent, leaf);
    expect_voxel_tiling(layout);
    expect_axis_tiling(layout);
    expect_tree_consistent(layout);
  }
}

TEST(OctreeLayout, TilesLargeAnisotropicExtents) {
  const std::vector<std::pair<glm::u64vec3, glm::uvec3>> cases = {
      {{1024, 1024, 40}, {16, 16, 16}},
      {{795, 795, 795}, {32, 32, 32}},
      {{std::uint64_t(1) << 20, 3, 1}, {4096, 4, 4}},
  };
  for (const auto& [extent, leaf] : cases) {
    SCOPED_TRACE(testing::Message() << extent.x << "x" << extent.y << "x" << extent.z);
    const OctreeLayout layout(extent, leaf);
    expect_axis_tiling(layout);
  }
  const OctreeLayout thin({std::uint64_t(1) << 20, 3, 1}, {4096, 4, 4});
  EXPECT_EQ(thin.depth_count(), 9u);  // 2^20 / 4096 = 2^8 leaves along x, one along y and z
  EXPECT_EQ(thin.leaf_count(), 256u);
  expect_tree_consistent(thin);
}

TEST(OctreeLayout, SplitsOnlyAxesThatAreNotMuchSmaller) {
  {
    // Node extent (4, 2, 2) in leaves: only x splits first (thesis §8.4.1).
    const OctreeLayout l({64, 32, 32}, {16, 16, 16});
    ASSERT_EQ(l.depth_count(), 3u);
    EXPECT_EQ(l.depth(1).split, glm::uvec3(1, 0, 0));
    EXPECT_EQ(l.depth(2).split, glm::uvec3(1, 1, 1));
    EXPECT_EQ(l.depth(1).node_extent, glm::u64vec3(32, 32, 32));
    EXPECT_EQ(l.depth(2).node_extent, glm::u64vec3(16, 16, 16));
    EXPECT_EQ(l.node_count(), 1u + 2u + 16u);
  }
  {
    // 1024x1024x40 with 16³ leaves: 64x64x3 leaves -> x and y halve 4 times before z joins.
    const OctreeLayout l({1024, 1024, 40}, {16, 16, 16});
    ASSERT_EQ(l.depth_count(), 7u);
    for (std::uint32_t d = 1; d <= 4; ++d) EXPECT_EQ(l.depth(d).split, glm::uvec3(1, 1, 0));
    for (std::uint32_t d = 5; d <= 6; ++d) EXPECT_EQ(l.depth(d).split, glm::uvec3(1, 1, 1));
    EXPECT_EQ(l.depth(6).count, glm::uvec3(64, 64, 4));
    EXPECT_EQ(l.depth(6).node_extent, glm::u64vec3(16, 16, 16));
  }
  {
    // An anisotropic leaf counts in leaf units: 64³ with 8x8x4 leaves is 8x8x16 leaves, so z
    // splits alone first.
    const OctreeLayout l({64, 64, 64}, {8, 8, 4});
    EXPECT_EQ(l.depth(1).split, glm::uvec3(0, 0, 1));
    EXPECT_EQ(l.depth(2).split, glm::uvec3(1, 1, 1));
    EXPECT_EQ(l.depth(l.leaf_depth()).node_extent, glm::u64vec3(8, 8, 4));
  }
  {
    // (4, 3, 2) leaves: padded (4, 4, 2) -> x and y split, z waits.
    const OctreeLayout l({64, 48, 32}, {16, 16, 16});
    EXPECT_EQ(l.depth(1).split, glm::uvec3(1, 1, 0));
    EXPECT_EQ(l.depth(2).split, glm::uvec3(1, 1, 1));
  }
}

TEST(OctreeLayout, StopsAtTheFirstDepthWithinTheLeafSize) {
  for (const glm::uvec3 leaf :
       {glm::uvec3(8), glm::uvec3(16), glm::uvec3(32), glm::uvec3(8, 8, 4), glm::uvec3(5, 7, 3)}) {
    const OctreeLayout l({200, 120, 61}, leaf);
    const glm::u64vec3 last = l.depth(l.leaf_depth()).node_extent;
    for (int a = 0; a < 3; ++a) EXPECT_LE(last[a], leaf[a]);
    if (l.depth_count() > 1) {
      const glm::u64vec3 prev = l.depth(l.leaf_depth() - 1).node_extent;
      EXPECT_TRUE(prev.x > leaf.x || prev.y > leaf.y || prev.z > leaf.z);
    }
  }
}

TEST(OctreeLayout, NodeRangeMatchesBruteForceOverlap) {
  const OctreeLayout layout({40, 33, 21}, {4, 8, 4});
  std::mt19937 rng(7);
  for (int iter = 0; iter < 300; ++iter) {
    Box3 box;
    for (int a = 0; a < 3; ++a) {
      const std::int64_t e = std::int64_t(layout.extent0()[a]);
      std::uniform_int_distribution<std::int64_t> pick(-3, e + 3);
      std::int64_t p = pick(rng), q = pick(rng);
      if (p > q) std::swap(p, q);
      box.lo[a] = p;
      box.hi[a] = q + 1;
    }
    for (std::uint32_t d = 0; d < layout.depth_count(); ++d) {
      std::set<std::uint64_t> expected;
      const OctreeDepth& dep = layout.depth(d);
      for (std::uint64_t n = dep.first_node; n < dep.first_node + dep.node_count; ++n) {
        if (overlaps(layout.node_box(n), box)) expected.insert(n);
      }
      std::set<std::uint64_t> got;
      layout.for_each_node(d, layout.node_range(d, box),
                           [&](std::uint64_t n, glm::uvec3) { got.insert(n); });
      ASSERT_EQ(got, expected) << "depth " << d;
    }
  }
}

TEST(OctreeLayout, RejectsBadParameters) {
  EXPECT_RESOCT_ERROR(OctreeLayout({64, 64, 64}, {0, 8, 8}), ErrorCode::invalid_argument,
                      "leaf_size");
  EXPECT_RESOCT_ERROR(OctreeLayout({64, 64, 64}, {8, 8, 1u << 21}), ErrorCode::invalid_argument,
                      "leaf_size");
  EXPECT_RESOCT_ERROR(OctreeLayout({0, 64, 64}, {8, 8, 8}), ErrorCode::invalid_argument, "extent");
  EXPECT_RESOCT_ERROR(OctreeLayout({65536, 65536, 65536}, {1, 1, 1}), ErrorCode::invalid_argument,
                      "leaf_size");
  EXPECT_RESOCT_ERROR(OctreeLayout({65536, 65536, 65536}, {1, 1, 1}), ErrorCode::invalid_argument,
                      "2^31");
  const OctreeLayout ok({65536, 65536, 65536}, {512, 512, 512});  // 2^21 leaves is fine
  EXPECT_EQ(ok.leaf_count(), std::uint64_t(1) << 21);
  EXPECT_RESOCT_ERROR(ok.depth_of(ok.node_count()), ErrorCode::out_of_range, "past the");
}

}  // namespace
}  // namespace resoct
