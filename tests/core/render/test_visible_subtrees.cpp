// The frame's visible-subtree bits (render/visible_subtrees.hpp) on a hand-made octree of three
// depths (1, 8 and 64 nodes; one record slot), against what the residency descent would find:
// a bit only where no node at or below it, down to the depth limit, is unknown, and none is
// hidden or (with an allowance, TuningOptions::skip_min_samples) too little is for a descent to
// pay.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/base/error.hpp"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/render/visible_subtrees.hpp"

namespace resoct::test {
namespace {

namespace k = resoct::kernel;

constexpr std::uint32_t kNodes = 1 + 8 + 64;

std::vector<k::ResoctDepthInfo> depths() {
  std::vector<k::ResoctDepthInfo> out;
  std::uint32_t first = 0;
  for (std::uint32_t d = 0; d < 3; ++d) {
    k::ResoctDepthInfo D{};
    D.count_x = D.count_y = D.count_z = 1u << d;
    D.count_log2_x = D.count_log2_y = D.count_log2_z = d;
    D.child_shift = d == 0 ? 0u : 3u;
    D.split_x = D.split_y = D.split_z = d == 0 ? 0u : 1u;
    D.first_node = first;
    D.node_extent_x = D.node_extent_y = D.node_extent_z = 32u >> d;
    // Each depth's child bits below the parent's: x lowest, then y, then z.
    for (std::uint32_t e = 1; e <= d; ++e) {
      D.axis_bits_x = (D.axis_bits_x << 3) | 1u;
      D.axis_bits_y = (D.axis_bits_y << 3) | 2u;
      D.axis_bits_z = (D.axis_bits_z << 3) | 4u;
    }
    first += D.count_x * D.count_y * D.count_z;
    out.push_back(D);
  }
  return out;
}

// A transfer function that shows [lo, 1] (normalized): its quantized hull and bins.
k::ResoctSlotInfo shows_from(double lo) {
  k::ResoctSlotInfo s{};
  s.slot = 0;
  s.vis_lo16 = std::uint32_t(lo * 65535.0);
  s.vis_hi16 = 65535u;
  s.vis_bins = 0xFFFFFFFFu << (s.vis_lo16 >> 11u);
  return s;
}

struct Tree {
  std::vector<std::uint32_t> words = std::vector<std::uint32_t>(kNodes * k::RESOCT_NODE_WORDS, 0u);
  // Every node VALID with the range [0.3, 0.9].
  Tree() {
    for (std::uint32_t n = 0; n < kNodes; ++n) set(n, k::RESOCT_NODE_VALID, 0.3, 0.9);
  }
  void set(std::uint32_t node, std::uint32_t state, double lo, double hi) {
    const std::uint32_t base = node * k::RESOCT_NODE_WORDS;
    words[base + k::RESOCT_NODE_FLAGS] = k::resoct_node_make_flags(state, 0u);
    words[base + k::RESOCT_NODE_MINMAX] =
        k::resoct_node_pack_minmax(std::uint32_t(lo * 65535.0), std::uint32_t(hi * 65535.0));
  }
  std::vector<std::uint32_t> bits(std::vector<k::ResoctSlotInfo> slots, std::uint32_t start = 0,
                                  std::uint32_t limit = 2, glm::uvec3 extent = glm::uvec3(32u),
                                  std::vector<std::uint16_t> allowance = {}) const {
    std::vector<std::uint32_t> out;
    build_visible_subtrees(words, 1, depths(), slots, extent, start, limit, out, allowance);
    return out;
  }
};

// Leaf 37 (depth 2, local 28) lies in depth-1 node local 3 (node 4).
constexpr std::uint32_t kLeaf = 9 + 28;
constexpr std::uint32_t kLeafParent = 1 + 3;

TEST(VisibleSubtrees, EveryNodeShownSetsEveryBitAboveTheLimit) {
  const auto bits = Tree().bits({shows_from(0.1)});
  ASSERT_EQ(bits.size(), kNodes);
  for (std::uint32_t n = 0; n < 9; ++n) EXPECT_EQ(bits[n], 1u) << "node " << n;
  for (std::uint32_t n = 9; n < kNodes; ++n) EXPECT_EQ(bits[n], 0u) << "leaf " << n;
}

TEST(VisibleSubtrees, AHiddenOrUnknownLeafClearsItsAncestors) {
  for (std::uint32_t state : {k::RESOCT_NODE_VALID, k::RESOCT_NODE_INVALID}) {
    Tree t;
    t.set(kLeaf, state, 0.0, 0.05);  // hidden below 0.1 (VALID) or unknown (INVALID)
    const auto bits = t.bits({shows_from(0.1)});
    EXPECT_EQ(bits[0], 0u) << "state " << state;
    for (std::uint32_t n = 1; n < 9; ++n) {
      EXPECT_EQ(bits[n], n == kLeafParent ? 0u : 1u) << "state " << state << ", node " << n;
    }
  }
}

TEST(VisibleSubtrees, ARangeThatStraddlesHiddenValuesIsNotHidden) {
  Tree t;
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.0, 0.2);  // hidden below 0.1, but reaches past it
  EXPECT_EQ(t.bits({shows_from(0.1)})[0], 1u);
}

TEST(VisibleSubtrees, AHomogeneousNodeHasNoBitButItsParentHas) {
  Tree t;
  t.set(kLeafParent, k::RESOCT_NODE_VALID, 0.5, 0.5);
  const auto bits = t.bits({shows_from(0.1)});
  EXPECT_EQ(bits[kLeafParent], 0u) << "its value is used without sampling";
  EXPECT_EQ(bits[0], 1u) << "below the root it is sampled, to the same value";
}

TEST(VisibleSubtreesLimits, NodesPastTheDepthLimitOrAboveTheStartAreNotRead) {
  Tree t;
  t.set(kLeaf, k::RESOCT_NODE_INVALID, 0.0, 0.0);
  const auto to_depth_1 = t.bits({shows_from(0.1)}, 0, 1);
  EXPECT_EQ(to_depth_1[0], 1u) << "no ray descends to the unknown leaf";
  for (std::uint32_t n = 1; n < kNodes; ++n) EXPECT_EQ(to_depth_1[n], 0u) << "node " << n;
  const auto from_depth_1 = Tree().bits({shows_from(0.1)}, 1, 2);
  EXPECT_EQ(from_depth_1[0], 0u);
  EXPECT_EQ(from_depth_1[1], 1u);
}

// The octree's node counts are powers of two: in a volume 20 voxels deep, the leaves at z = 24..31
// hold no voxel, no ray reaches them and their records stay INVALID. They count as shown.
TEST(VisibleSubtreesLimits, NodesOutsideTheVolumeDoNotClearTheirAncestors) {
  Tree t;
  for (std::uint32_t leaf = 0; leaf < 64; ++leaf) {
    // z coordinate 3: its high bit from the parent's child bits (bit 5), its low bit (bit 2).
    if ((leaf & 0b100100u) == 0b100100u) t.set(9 + leaf, k::RESOCT_NODE_INVALID, 0.0, 0.0);
  }
  EXPECT_EQ(t.bits({shows_from(0.1)})[0], 0u) << "in a 32-voxel volume they are unknown";
  const auto bits = t.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32, 32, 20));
  EXPECT_EQ(bits[0], 1u);
  for (std::uint32_t n = 1; n < 9; ++n) EXPECT_EQ(bits[n], 1u) << "node " << n;
}

TEST(VisibleSubtreesLimits, EachSlotTableEntryHasItsOwnBit) {
  k::ResoctSlotInfo hides_all = shows_from(0.95);  // the data's values end at 0.9
  k::ResoctSlotInfo invisible{};                   // shows nothing: not live, no bit
  const auto bits = Tree().bits({shows_from(0.1), hides_all, invisible, shows_from(0.0)});
  EXPECT_EQ(bits[0], 0b1001u);
}

TEST(VisibleSubtreesLimits, ShortOctreesAndForeignSlotsAreRejected) {
  Tree t;
  std::vector<std::uint32_t> out;
  const std::vector<std::uint32_t> short_words(t.words.begin(), t.words.end() - 1);
  EXPECT_THROW(build_visible_subtrees(short_words, 1, depths(), std::vector{shows_from(0.1)},
                                      glm::uvec3(32u), 0, 2, out),
               Error);
  k::ResoctSlotInfo foreign = shows_from(0.1);
  foreign.slot = 1;
  EXPECT_THROW(build_visible_subtrees(t.words, 1, depths(), std::vector{foreign}, glm::uvec3(32u),
                                      0, 2, out),
               Error);
}

// A frame whose shortest step is one voxel of a 32³ volume in a unit box: the root is 32 samples
// across, its children 16, the leaves 8.
k::ResoctFrame voxel_step_frame() {
  k::ResoctFrame f{};
  f.voxels_per_box_x = f.voxels_per_box_y = f.voxels_per_box_z = 32.0f;
  f.finest_voxel_x = f.finest_voxel_y = f.finest_voxel_z = 1.0f / 32.0f;
  f.step_scale = 1.0f;
  f.ref_step = 1.0f / 32.0f;
  return f;
}

// What a depth allows hidden: skip_min_samples over the samples a ray takes across its nodes.
TEST(VisibleSubtreesAllowance, IsTheShareOfANodeWhoseSamplesWouldSaveTooFewToDescend) {
  std::vector<std::uint16_t> allowance;
  hidden_allowance(voxel_step_frame(), depths(), 8.0f, allowance);
  ASSERT_EQ(allowance.size(), 3u);
  EXPECT_EQ(allowance[0], 16383u) << "8 of 32 samples: a quarter, rounded down";
  EXPECT_EQ(allowance[1], 32767u) << "8 of 16";
  EXPECT_EQ(allowance[2], kHiddenWhole) << "a leaf is crossed in 8 samples: nothing it hides pays";
  hidden_allowance(voxel_step_frame(), depths(), 0.0f, allowance);
  EXPECT_EQ(allowance, std::vector<std::uint16_t>(3, 0u)) << "0: only subtrees hiding nothing";
  k::ResoctFrame coarse = voxel_step_frame();
  coarse.step_scale = 2.0f;  // half as many samples: twice the share
  hidden_allowance(coarse, depths(), 4.0f, allowance);
  EXPECT_EQ(allowance[0], 16383u);
}

// One hidden leaf of 64: its parent hides an eighth (8192 of 65535, rounded up), the root a
// sixty-fourth (1024). Each gets its bit when its depth allows that much.
TEST(VisibleSubtreesAllowance, ANodeHidingNoMoreThanItsDepthAllowsKeepsItsBit) {
  Tree t;
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.0, 0.05);
  const auto strict = t.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), {0, 0, 0});
  EXPECT_EQ(strict[0], 0u);
  EXPECT_EQ(strict[kLeafParent], 0u);
  const auto root_only = t.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), {1024, 8191, 0});
  EXPECT_EQ(root_only[0], 1u) << "1024 hidden, 1024 allowed";
  EXPECT_EQ(root_only[kLeafParent], 0u) << "8192 hidden, 8191 allowed";
  const auto none = t.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), {1023, 8191, 0});
  EXPECT_EQ(none[0], 0u) << "1024 hidden, 1023 allowed";
  const auto both = t.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), {1024, 8192, 0});
  EXPECT_EQ(both[0], 1u);
  EXPECT_EQ(both[kLeafParent], 1u);
  for (std::uint32_t n = 1; n < 9; ++n) {
    if (n != kLeafParent) EXPECT_EQ(both[n], 1u) << "node " << n << " hides nothing";
  }
}

// The allowance widens what a bit may hide, never what it must know: an INVALID record below
// still clears it (the descent would request it), an EMPTY or homogeneous node never gets one,
// and nodes inside an EMPTY node are not read (no ray's descent reaches them).
TEST(VisibleSubtreesAllowance, UnknownRecordsStillClearTheBitAndHiddenNodesGetNone) {
  const std::vector<std::uint16_t> all(3, std::uint16_t(kHiddenWhole));
  Tree unknown;
  unknown.set(kLeaf, k::RESOCT_NODE_INVALID, 0.0, 0.0);
  const auto u = unknown.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), all);
  EXPECT_EQ(u[0], 0u);
  EXPECT_EQ(u[kLeafParent], 0u);
  Tree hidden;
  hidden.set(kLeafParent, k::RESOCT_NODE_VALID, 0.0, 0.05);
  hidden.set(kLeaf, k::RESOCT_NODE_INVALID, 0.0, 0.0);  // below an EMPTY node: never requested
  const auto h = hidden.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), all);
  EXPECT_EQ(h[0], 1u) << "an eighth hidden, all of it allowed; the unknown leaf is not read";
  EXPECT_EQ(h[kLeafParent], 0u) << "an EMPTY node is skipped, not marched";
  EXPECT_EQ(hidden.bits({shows_from(0.1)})[0], 0u) << "without an allowance";
  Tree homogeneous;
  homogeneous.set(kLeafParent, k::RESOCT_NODE_VALID, 0.5, 0.5);
  EXPECT_EQ(homogeneous.bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), all)[kLeafParent], 0u);
  EXPECT_THROW(Tree().bits({shows_from(0.1)}, 0, 2, glm::uvec3(32u), {0, 0}), Error)
      << "one value per depth";
}

// A hidden node that holds whole bricks of the finest level sampled (at or above the entry's
// brick depth) is never widened over: sampling it would request bricks no descent reads.
TEST(VisibleSubtreesAllowance, HiddenNodesOfWholeBricksKeepTheirAncestorsBitsCleared) {
  const std::vector<std::uint16_t> all(3, std::uint16_t(kHiddenWhole));
  Tree t;
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.0, 0.05);
  std::vector<std::uint32_t> out;
  const std::vector<std::uint32_t> leaves_are_bricks{2}, parents_are_bricks{1};
  build_visible_subtrees(t.words, 1, depths(), std::vector{shows_from(0.1)}, glm::uvec3(32u), 0, 2,
                         out, all, leaves_are_bricks);
  EXPECT_EQ(out[0], 0u) << "the hidden leaf is a whole brick";
  EXPECT_EQ(out[kLeafParent], 0u);
  build_visible_subtrees(t.words, 1, depths(), std::vector{shows_from(0.1)}, glm::uvec3(32u), 0, 2,
                         out, all, parents_are_bricks);
  EXPECT_EQ(out[0], 1u) << "the hidden leaf is an eighth of a brick its neighbours show";
  EXPECT_EQ(out[kLeafParent], 1u);
  EXPECT_THROW(
      build_visible_subtrees(t.words, 1, depths(), std::vector{shows_from(0.1)}, glm::uvec3(32u), 0,
                             2, out, all, std::vector<std::uint32_t>{1, 1}),
      Error)
      << "one brick depth per entry";
  std::vector<k::ResoctLevelInfo> levels(2);
  levels[0].node_depth = 2;
  levels[1].node_depth = 0xFFFFFFFFu;  // no depth holds these bricks
  k::ResoctSlotInfo fine = shows_from(0.1), coarse = shows_from(0.1);
  coarse.finest_level = 1;
  std::vector<std::uint32_t> depth;
  brick_depths(levels, std::vector{fine, coarse}, depth);
  EXPECT_EQ(depth, (std::vector<std::uint32_t>{2u, 0xFFFFFFFFu}));
}

// Hidden nodes of whole bricks that are resident EMPTY pages (only zeros) at every level the entry
// samples hide nothing: a march below a set bit skips each such brick at its page entry, as the
// page table does, and requests nothing.
TEST(VisibleSubtreesAllowance, ResidentEmptyPagesHideNothing) {
  const std::vector<std::uint32_t> leaves_are_bricks{2}, parents_are_bricks{1};
  const auto residency = [](Tree& t, std::uint32_t node, std::uint32_t levels) {
    t.words[node * k::RESOCT_NODE_WORDS + k::RESOCT_NODE_RESIDENCY] = levels;
  };
  const auto bits = [](const Tree& t, const k::ResoctSlotInfo& s,
                       const std::vector<std::uint32_t>& brick_depth) {
    std::vector<std::uint32_t> out;
    build_visible_subtrees(t.words, 1, depths(), std::vector{s}, glm::uvec3(32u), 0, 2, out, {},
                           brick_depth);
    return out;
  };
  k::ResoctSlotInfo s = shows_from(0.1);
  Tree t;
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.0, 0.0);
  EXPECT_EQ(bits(t, s, leaves_are_bricks)[0], 0u) << "not resident: the march would request it";
  residency(t, kLeaf, 0b1u);
  EXPECT_EQ(bits(t, s, leaves_are_bricks)[0], 1u);
  EXPECT_EQ(bits(t, s, leaves_are_bricks)[kLeafParent], 1u);
  EXPECT_EQ(bits(t, s, {})[0], 0u) << "without brick depths no page is known to be EMPTY";
  EXPECT_EQ(bits(t, s, parents_are_bricks)[0], 0u) << "an eighth of a brick: not an EMPTY page";
  k::ResoctSlotInfo coarse = s;
  coarse.coarsest_level = 1;
  EXPECT_EQ(bits(t, coarse, leaves_are_bricks)[0], 0u) << "level 1 is not resident";
  residency(t, kLeaf, 0b11u);
  EXPECT_EQ(bits(t, coarse, leaves_are_bricks)[0], 1u);
  k::ResoctSlotInfo offset = s;
  offset.zero_value = -0.25f;  // raw 0 is not the range's bottom: [0, 0] is no EMPTY page
  EXPECT_EQ(bits(t, offset, leaves_are_bricks)[0], 0u);
  Tree low;
  low.set(kLeaf, k::RESOCT_NODE_VALID, 0.0, 0.05);  // hidden, but not only zeros
  residency(low, kLeaf, 0b1u);
  EXPECT_EQ(bits(low, s, leaves_are_bricks)[0], 0u);
  Tree approx;
  approx.set(kLeaf, k::RESOCT_NODE_APPROX, 0.0, 0.0);  // may be too narrow
  residency(approx, kLeaf, 0b1u);
  EXPECT_EQ(bits(approx, s, leaves_are_bricks)[0], 0u);
  // A node above the bricks is free when every child is.
  Tree above;
  above.set(kLeafParent, k::RESOCT_NODE_VALID, 0.0, 0.0);
  for (std::uint32_t c = 0; c < 8; ++c) {
    const std::uint32_t leaf = 9 + 3 * 8 + c;  // the children of depth-1 local 3
    above.set(leaf, k::RESOCT_NODE_VALID, 0.0, 0.0);
    residency(above, leaf, c == 5 ? 0u : 0b1u);
  }
  EXPECT_EQ(bits(above, s, leaves_are_bricks)[0], 0u) << "one child's brick is not resident";
  residency(above, 9 + 3 * 8 + 5, 0b1u);
  EXPECT_EQ(bits(above, s, leaves_are_bricks)[0], 1u);
  residency(above, kLeafParent, 0b1u);
  EXPECT_EQ(bits(above, s, parents_are_bricks)[0], 1u) << "the parent is the brick";
}

// The depth limit is the deepest traversal depth of any ray: an axis-aligned ray's step, and the
// finest level any shown entry samples.
TEST(VisibleSubtreesLimits, TheDepthLimitFollowsTheShortestStepAndTheFinestLevel) {
  k::ResoctFrame f{};
  f.voxels_per_box_x = f.voxels_per_box_y = f.voxels_per_box_z = 32.0f;
  f.finest_voxel_x = f.finest_voxel_y = f.finest_voxel_z = 1.0f / 32.0f;
  f.step_scale = 1.0f;
  f.ref_step = 1.0f / 32.0f;
  std::vector<k::ResoctLevelInfo> levels(4);
  for (std::uint32_t l = 0; l < 4; ++l) {
    levels[l].factor_log2_x = levels[l].factor_log2_y = levels[l].factor_log2_z = l;
  }
  k::ResoctSlotInfo s = shows_from(0.1);
  EXPECT_EQ(deepest_traversal_depth(f, levels, depths(), std::vector{s}), 2u);
  s.finest_level = 3;  // 8-voxel leaves hold one level-3 voxel: depth 1 (two of them)
  EXPECT_EQ(deepest_traversal_depth(f, levels, depths(), std::vector{s}), 1u);
  s.finest_level = 0;
  f.step_scale = 10.0f;  // steps of 10 voxels: nodes of 16 are the smallest that long
  EXPECT_EQ(deepest_traversal_depth(f, levels, depths(), std::vector{s}), 1u);
}

// The incremental update (VisibleSubtreeBuilder::update) against a full build of the same words:
// two record slots, two entries, nodes outside the volume (extent 24 of the 32 the counts span),
// random records changed a few nodes at a time, for every start depth and depth limit.
TEST(VisibleSubtreeUpdates, GiveWhatAFullBuildOfTheChangedRecordsGives) {
  constexpr std::uint32_t kSlots = 2;
  const std::vector<k::ResoctSlotInfo> entries = [] {
    std::vector<k::ResoctSlotInfo> e{shows_from(0.1), shows_from(0.4)};
    e[1].slot = 1;
    return e;
  }();
  const glm::uvec3 extent(32, 24, 32);
  std::mt19937 rng(20261128);
  auto draw = [&rng](std::uint32_t n) { return std::uint32_t(rng() % n); };
  const std::vector<std::vector<std::uint16_t>> allowances = {{}, {3000, 20000, 65535}};
  // Without brick depths, and with entry 0's bricks at depth 1 and entry 1's at the leaves, where
  // resident EMPTY pages hide nothing.
  const std::vector<std::vector<std::uint32_t>> brick_depths = {{}, {}, {1, 2}};
  for (std::size_t variant = 0; variant < brick_depths.size(); ++variant) {
    const std::vector<std::uint16_t>& allowance = allowances[std::min<std::size_t>(variant, 1)];
    const std::vector<std::uint32_t>& brick_depth = brick_depths[variant];
    for (std::uint32_t start = 0; start < 2; ++start) {
      for (std::uint32_t limit = start + 1; limit < 3; ++limit) {
        std::vector<std::uint32_t> words(kNodes * kSlots * k::RESOCT_NODE_WORDS, 0u);
        auto set_random = [&](std::uint32_t node) {
          for (std::uint32_t s = 0; s < kSlots; ++s) {
            const std::uint32_t base = k::resoct_node_base(node, s, kSlots);
            // Mostly shown ranges, so that bits exist for changes to clear; some hidden, unknown,
            // homogeneous ones, and only zeros, resident or not.
            const std::uint32_t kind = draw(24);
            const std::uint32_t lo = kind == 0   ? draw(6000)
                                     : kind == 1 ? 30000u
                                     : kind == 3 ? 0u
                                                 : 20000u + draw(20000);
            const std::uint32_t hi = kind == 0                ? lo + draw(100)
                                     : kind == 1 || kind == 3 ? lo
                                                              : lo + draw(20000);
            words[base + k::RESOCT_NODE_FLAGS] = k::resoct_node_make_flags(
                kind == 2 ? k::RESOCT_NODE_INVALID : k::RESOCT_NODE_VALID, 0u);
            words[base + k::RESOCT_NODE_MINMAX] = k::resoct_node_pack_minmax(lo, hi);
            words[base + k::RESOCT_NODE_RESIDENCY] = draw(4) == 0 ? 0u : 1u;
          }
        };
        for (std::uint32_t n = 0; n < kNodes; ++n) set_random(n);
        VisibleSubtreeBuilder builder;
        std::vector<std::uint32_t> kept;
        builder.build(words, kSlots, depths(), entries, extent, start, limit, kept, allowance,
                      brick_depth);
        std::uint64_t changed_words = 0;
        for (int round = 0; round < 300; ++round) {
          std::vector<std::uint32_t> changed(1 + draw(4));
          for (std::uint32_t& n : changed) {
            n = draw(kNodes);
            set_random(n);
          }
          changed.push_back(changed.front());  // repeats are allowed
          changed_words += builder.update(words, changed, kept).words_changed;
          std::vector<std::uint32_t> fresh;
          build_visible_subtrees(words, kSlots, depths(), entries, extent, start, limit, fresh,
                                 allowance, brick_depth);
          ASSERT_EQ(kept, fresh) << "start " << start << ", limit " << limit << ", round " << round
                                 << ", variant " << variant;
        }
        EXPECT_GE(changed_words, 10u)
            << "the rounds must change bits for the check to mean anything";
      }
    }
  }
}

// An update walks up from a changed record only while the subtree masks change.
TEST(VisibleSubtreeUpdates, RecomputeOnlyThePathsWhoseMasksChange) {
  Tree t;
  VisibleSubtreeBuilder builder;
  std::vector<std::uint32_t> bits;
  builder.build(t.words, 1, depths(), std::vector{shows_from(0.1)}, glm::uvec3(32u), 0, 2, bits);
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.0, 0.05);  // now hidden: its parent and the root lose bits
  const std::uint32_t leaf[] = {kLeaf};
  const VisibleSubtreeUpdate hidden = builder.update(t.words, leaf, bits);
  EXPECT_EQ(hidden.recomputed, 3u);
  EXPECT_EQ(hidden.words_changed, 2u);
  EXPECT_EQ(bits[kLeafParent], 0u);
  EXPECT_EQ(bits[0], 0u);
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.2, 0.6);  // shown again, with another range
  EXPECT_EQ(builder.update(t.words, leaf, bits).words_changed, 2u);
  EXPECT_EQ(bits, t.bits({shows_from(0.1)}));
  t.set(kLeaf, k::RESOCT_NODE_VALID, 0.3, 0.7);  // still shown: the leaf alone is recomputed
  const VisibleSubtreeUpdate same = builder.update(t.words, leaf, bits);
  EXPECT_EQ(same.recomputed, 1u);
  EXPECT_EQ(same.words_changed, 0u);
}

TEST(VisibleSubtreeUpdates, WithoutABuildOrPastTheTreeAreRejected) {
  Tree t;
  VisibleSubtreeBuilder builder;
  std::vector<std::uint32_t> bits(kNodes, 0u);
  const std::uint32_t leaf[] = {kLeaf};
  auto message = [&](const std::uint32_t* nodes) {
    try {
      builder.update(t.words, std::span(nodes, 1), bits);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(leaf).find("octree"), std::string::npos) << "no build yet";
  builder.build(t.words, 1, depths(), std::vector{shows_from(0.1)}, glm::uvec3(32u), 0, 2, bits);
  const std::uint32_t past[] = {kNodes};
  EXPECT_NE(message(past).find("nodes"), std::string::npos);
  std::vector<std::uint32_t> other(kNodes - 1, 0u);
  EXPECT_THROW(builder.update(t.words, leaf, other), Error) << "bits of another tree";
}

}  // namespace
}  // namespace resoct::test
