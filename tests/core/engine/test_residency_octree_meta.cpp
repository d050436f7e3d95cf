// Residency octree metadata: conservative quantization, the node word helpers, and culling
// metadata checked against the true voxels of a volume.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/base/error.hpp"
#include "resoct/engine/leaf_scan.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "support/expect_error.hpp"

namespace resoct {
namespace {

namespace k = resoct::kernel;

static_assert(k::RESOCT_NODE_WORDS * sizeof(std::uint32_t) == ResidencyOctree::bytes_per_node(1));
static_assert(k::RESOCT_NODE_RESIDENCY == 0 && k::RESOCT_NODE_MINMAX == 1 &&
              k::RESOCT_NODE_OCCUPANCY == 2 && k::RESOCT_NODE_FLAGS == 3);
static_assert(k::RESOCT_NODE_INVALID == 0, "all-zero records must read as INVALID");

double clamp_to(double v, const ValueRange& r) {
  return std::clamp(v, r.lo, r.hi);
}

void expect_conservative(double v, const ValueRange& r) {
  const std::uint32_t qmin = octree_quantize_min(v, r);
  const std::uint32_t qmax = octree_quantize_max(v, r);
  const double c = clamp_to(v, r);
  ASSERT_LE(qmin, 65535u);
  ASSERT_LE(qmax, 65535u);
  ASSERT_LE(octree_dequantize(qmin, r), c) << v << " in [" << r.lo << ", " << r.hi << "]";
  ASSERT_GE(octree_dequantize(qmax, r), c) << v << " in [" << r.lo << ", " << r.hi << "]";
  // Tight: one step further would no longer bound the value.
  if (qmin < 65535u) {
    ASSERT_GT(octree_dequantize(qmin + 1, r), c);
  }
  if (qmax > 0u) {
    ASSERT_LT(octree_dequantize(qmax - 1, r), c);
  }
}

TEST(OctreeQuantization, U16RangesAreConservativeAndTight) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> u16(0, 65535);
  for (int i = 0; i < 20000; ++i) {
    int a = u16(rng), b = u16(rng);
    if (a == b) continue;
    if (a > b) std::swap(a, b);
    const ValueRange r{double(a), double(b)};
    expect_conservative(double(u16(rng)), r);
    expect_conservative(double(a), r);
    expect_conservative(double(b), r);
  }
  // Over the full u16 range quantization is the identity.
  const ValueRange full{0.0, 65535.0};
  for (std::uint32_t v : {0u, 1u, 2u, 1000u, 32767u, 65534u, 65535u}) {
    EXPECT_EQ(octree_quantize_min(double(v), full), v);
    EXPECT_EQ(octree_quantize_max(double(v), full), v);
  }
}

TEST(OctreeQuantization, F32RangesAreConservativeAndTight) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const double lo = double(float((unit(rng) - 0.5) * 2e6));
    const double width = std::pow(10.0, unit(rng) * 9.0 - 3.0);
    const ValueRange r{lo, lo + width};
    if (!(r.lo < r.hi)) continue;
    const double v = double(float(lo + width * (unit(rng) * 1.4 - 0.2)));
    expect_conservative(v, r);
  }
}

TEST(OctreeQuantization, NanAndInfinityAreHandledConservatively) {
  const ValueRange r{0.0, 1.0};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(octree_quantize_min(nan, r), 0u);
  EXPECT_EQ(octree_quantize_max(nan, r), 65535u);
  EXPECT_EQ(octree_quantize_min(-inf, r), 0u);
  EXPECT_EQ(octree_quantize_max(inf, r), 65535u);
  EXPECT_EQ(octree_quantize_min(inf, r), 65535u);
  EXPECT_EQ(octree_quantize_max(-inf, r), 0u);
  EXPECT_EQ(octree_pack_range(nan, 0.5, r), 0u);
  EXPECT_EQ(octree_pack_range(inf, -inf, r), 0u);  // a region of only NaN
  EXPECT_TRUE(k::resoct_node_range_empty(octree_pack_range(inf, -inf, r)));
  EXPECT_FALSE(k::resoct_node_range_empty(octree_pack_range(0.5, 0.5, r)));
}

TEST(OctreeNodeWords, MinMaxPackingAndMerge) {
  std::mt19937 rng(13);
  std::uniform_int_distribution<std::uint32_t> q(0, 65535);
  EXPECT_TRUE(k::resoct_node_range_empty(0u));
  for (int i = 0; i < 10000; ++i) {
    std::uint32_t a0 = q(rng), a1 = q(rng), b0 = q(rng), b1 = q(rng);
    if (a0 > a1) std::swap(a0, a1);
    if (b0 > b1) std::swap(b0, b1);
    const std::uint32_t a = k::resoct_node_pack_minmax(a0, a1);
    const std::uint32_t b = k::resoct_node_pack_minmax(b0, b1);
    ASSERT_EQ(k::resoct_node_min16(a), a0);
    ASSERT_EQ(k::resoct_node_max16(a), a1);
    const std::uint32_t m = k::resoct_node_merge_minmax(a, b);
    ASSERT_EQ(k::resoct_node_min16(m), std::min(a0, b0));
    ASSERT_EQ(k::resoct_node_max16(m), std::max(a1, b1));
    ASSERT_EQ(k::resoct_node_merge_minmax(a, 0u), a);  // the empty record is neutral
    // Visibility: [a0, a1] against [b0, b1] with all bins visible.
    const bool overlap = a0 <= b1 && a1 >= b0;
    ASSERT_EQ(k::resoct_node_may_be_visible(a, 1u, b0, b1, ~0u), overlap);
    ASSERT_FALSE(k::resoct_node_may_be_visible(a, 0x0000ff00u, 0u, 65535u, 0x000000ffu));
  }
}

TEST(OctreeNodeWords, ResolutionSubstitutionLookups) {
  std::mt19937 rng(14);
  for (int i = 0; i < 5000; ++i) {
    const std::uint32_t mask = std::uint32_t(rng() & rng());
    const std::uint32_t level = rng() % 32;
    int coarser = -1, finer = -1;
    for (std::uint32_t l = level + 1; l < 32 && coarser < 0; ++l) {
      if (mask & (1u << l)) coarser = int(l);
    }
    for (int l = int(level) - 1; l >= 0 && finer < 0; --l) {
      if (mask & (1u << l)) finer = l;
    }
    ASSERT_EQ(k::resoct_node_next_coarser(mask, level), coarser);
    ASSERT_EQ(k::resoct_node_next_finer(mask, level), finer);
    ASSERT_EQ(k::resoct_node_partially_mapped(mask, level), ((mask >> level) & 1u) != 0u);
  }
  const std::uint32_t f = k::resoct_node_make_flags(k::RESOCT_NODE_APPROX, 17u);
  EXPECT_EQ(k::resoct_node_state(f), k::RESOCT_NODE_APPROX);
  EXPECT_EQ(k::resoct_node_approx_level(f), 17u);
  EXPECT_FALSE(k::resoct_node_has_metadata(0u));
}

// The record header must stay valid GLSL: compile a shader that uses every helper.
TEST(OctreeNodeWords, HeaderCompilesAsGlsl) {
  if (std::system("glslangValidator --version > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "glslangValidator not installed";
  }
  const std::string dir = std::string(RESOCT_BINARY_DIR) + "/octree_node_glsl";
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir + "/node.comp");
    f << "#version 450\n#extension GL_GOOGLE_include_directive : require\n"
         "#include \"resoct/kernel/octree_node.glsl.h\"\n"
         "layout(local_size_x = 1) in;\n"
         "layout(std430, binding = 0) buffer B { uint w[]; };\n"
         "void main() {\n"
         "  uint b = resoct_node_base(3u, 1u, 4u);\n"
         "  uint mm = resoct_node_merge_minmax(w[b + RESOCT_NODE_MINMAX],\n"
         "                                     resoct_node_pack_minmax(3u, 9u));\n"
         "  w[0] = mm + uint(resoct_node_next_coarser(w[b], 2u))\n"
         "       + uint(resoct_node_next_finer(w[b], 2u)) + resoct_node_min16(mm)\n"
         "       + resoct_node_max16(mm) + (resoct_node_range_empty(mm) ? 1u : 0u);\n"
         "  w[1] = resoct_node_may_be_visible(mm, w[2], 1u, 5u, 7u) ? 1u : 0u;\n"
         "  w[2] = resoct_node_make_flags(RESOCT_NODE_APPROX, 3u)\n"
         "       + resoct_node_approx_level(w[3]) + (resoct_node_has_metadata(w[3]) ? 1u : 0u)\n"
         "       + (resoct_node_partially_mapped(w[0], 1u) ? 1u : 0u)\n"
         "       + resoct_node_state(w[3]) + RESOCT_NODE_UNKNOWN + RESOCT_NODE_VALID;\n"
         "}\n";
  }
  const std::string cmd = "glslangValidator -V -I" + std::string(RESOCT_SOURCE_DIR) + "/include " +
                          dir + "/node.comp -o " + dir + "/node.spv > " + dir + "/log.txt 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "see " << dir << "/log.txt";
}

// A small f32 volume with blocky structure, NaN and out-of-range values, and the bricks and region
// metadata derived from it by brute force.
class VolumeFixture : public ::testing::Test {
 protected:
  static constexpr glm::u64vec3 kExtent{48, 40, 24};

  VolumeFixture() : hierarchy_(make_desc(), make_layout()) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    voxels_.resize(std::size_t(kExtent.x * kExtent.y * kExtent.z));
    std::vector<float> block(std::size_t(kExtent.x * kExtent.y * kExtent.z / 8 + 64));
    for (auto& b : block) b = unit(rng) * 1.3f - 0.15f;
    for (std::uint64_t z = 0; z < kExtent.z; ++z)
      for (std::uint64_t y = 0; y < kExtent.y; ++y)
        for (std::uint64_t x = 0; x < kExtent.x; ++x) {
          const std::size_t bi = std::size_t(x / 4 + 12 * (y / 4 + 10 * (z / 4)));
          float v = block[bi] + unit(rng) * 0.05f;
          if (unit(rng) < 0.01f) v = std::numeric_limits<float>::quiet_NaN();
          voxels_[index(x, y, z)] = v;
        }
  }
  static VolumeDesc make_desc() {
    VolumeDesc v;
    v.extent = kExtent;
    v.type = VoxelType::f32;
    return v;
  }
  static BrickLayout make_layout() {
    BrickLayout l;
    l.brick_size = glm::uvec3(8);
    return l;
  }
  static std::size_t index(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    return std::size_t(x + kExtent.x * (y + kExtent.y * z));
  }
  // Padded level-0 brick, clamped at the volume border.
  std::vector<std::byte> level0_brick(glm::uvec3 b) const {
    const glm::ivec3 p(hierarchy_.layout().padded_size());
    std::vector<std::byte> out(std::size_t(p.x * p.y * p.z) * 4);
    const glm::i64vec3 lo = hierarchy_.padded_box(0, b).lo;
    std::size_t i = 0;
    for (int z = 0; z < p.z; ++z)
      for (int y = 0; y < p.y; ++y)
        for (int x = 0; x < p.x; ++x, ++i) {
          const glm::i64vec3 c = glm::clamp(lo + glm::i64vec3(x, y, z), glm::i64vec3(0),
                                            glm::i64vec3(kExtent) - glm::i64vec3(1));
          const float v =
              voxels_[index(std::uint64_t(c.x), std::uint64_t(c.y), std::uint64_t(c.z))];
          std::memcpy(out.data() + 4 * i, &v, 4);
        }
    return out;
  }
  RegionMeta truth(const Box3& box) const {
    RegionMeta m;
    const ValueRange r{0.0, 1.0};
    for (std::int64_t z = box.lo.z; z < box.hi.z; ++z)
      for (std::int64_t y = box.lo.y; y < box.hi.y; ++y)
        for (std::int64_t x = box.lo.x; x < box.hi.x; ++x) {
          const double v = voxels_[index(std::uint64_t(x), std::uint64_t(y), std::uint64_t(z))];
          if (std::isnan(v)) continue;
          m.min = std::min(m.min, v);
          m.max = std::max(m.max, v);
          m.occupancy |= occupancy_bit(v, r);
        }
    return m;
  }
  // A VALID record bounds the clamped true values and covers their occupancy bins.
  void expect_valid_bounds(const ResidencyOctree& tree, std::uint64_t node, bool exact) const {
    const ValueRange r{0.0, 1.0};
    const RegionMeta t = truth(tree.layout().sampling_support(node));
    const std::uint32_t mm = tree.word(node, 0, k::RESOCT_NODE_MINMAX);
    const std::uint32_t occ = tree.word(node, 0, k::RESOCT_NODE_OCCUPANCY);
    ASSERT_EQ(occ & t.occupancy, t.occupancy) << "node " << node;
    if (t.min > t.max) return;  // only NaN: nothing to bound
    ASSERT_FALSE(k::resoct_node_range_empty(mm)) << "node " << node;
    ASSERT_LE(octree_dequantize(k::resoct_node_min16(mm), r), clamp_to(t.min, r));
    ASSERT_GE(octree_dequantize(k::resoct_node_max16(mm), r), clamp_to(t.max, r));
    if (exact) {
      ASSERT_EQ(occ, t.occupancy) << "node " << node;
      ASSERT_GT(octree_dequantize(k::resoct_node_min16(mm), r) + 1.0 / 65535.0, clamp_to(t.min, r));
      ASSERT_LT(octree_dequantize(k::resoct_node_max16(mm), r) - 1.0 / 65535.0, clamp_to(t.max, r));
    }
  }
  glm::uvec3 n_bricks_past() const { return {hierarchy_.level(0).bricks.x, 0, 0}; }
  std::uint32_t state(const ResidencyOctree& tree, std::uint64_t node) const {
    return k::resoct_node_state(tree.word(node, 0, k::RESOCT_NODE_FLAGS));
  }

  BrickHierarchy hierarchy_;
  std::vector<float> voxels_;
  ResidencyQuery nothing_resident_ = [](std::uint32_t, std::uint32_t, glm::uvec3) { return false; };
};

TEST_F(VolumeFixture, Level0BricksGiveExactLeavesAndValidAncestors) {
  ResidencyOctree tree(hierarchy_, OctreeLayout(kExtent, {4, 4, 4}), 1, nothing_resident_);
  const glm::uvec3 n = hierarchy_.level(0).bricks;
  for (std::uint32_t z = 0; z < n.z; ++z)
    for (std::uint32_t y = 0; y < n.y; ++y)
      for (std::uint32_t x = 0; x < n.x; ++x) {
        tree.metadata_from_brick(0, 0, {x, y, z}, level0_brick({x, y, z}));
      }
  const OctreeLayout& layout = tree.layout();
  for (std::uint64_t node = 0; node < layout.node_count(); ++node) {
    if (layout.node_box(node).empty()) {
      EXPECT_EQ(state(tree, node), k::RESOCT_NODE_INVALID);
      continue;
    }
    ASSERT_EQ(state(tree, node), k::RESOCT_NODE_VALID) << "node " << node;
    expect_valid_bounds(tree, node, /*exact=*/true);
  }
  const auto problem = tree.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;
}

TEST_F(VolumeFixture, RegionMetadataStaysConservativeUpTheTree) {
  ResidencyOctree tree(hierarchy_, OctreeLayout(kExtent, {4, 4, 4}), 1, nothing_resident_);
  const OctreeLayout& layout = tree.layout();
  std::mt19937 rng(22);
  std::set<std::uint64_t> supplied;
  for (int i = 0; i < 400; ++i) {
    std::uint64_t node = rng() % layout.node_count();
    while (layout.node_box(node).empty()) node = rng() % layout.node_count();
    supplied.insert(node);
    const Box3 box = layout.sampling_support(node);  // what the renderer queries
    RegionMeta m = truth(box);
    if (i % 3 == 0 && m.min <= m.max) {  // a looser but still conservative answer
      m.min -= 0.1;
      m.max += 0.1;
      m.occupancy = occupancy_span(m.min, m.max, ValueRange{0.0, 1.0});
    }
    tree.node_metadata(0, node, m);
    EXPECT_EQ(state(tree, node), k::RESOCT_NODE_VALID);
  }
  std::size_t valid = 0;
  for (std::uint64_t node = 0; node < layout.node_count(); ++node) {
    if (state(tree, node) == k::RESOCT_NODE_INVALID) continue;
    ASSERT_EQ(state(tree, node), k::RESOCT_NODE_VALID);
    expect_valid_bounds(tree, node, /*exact=*/false);
    ++valid;
  }
  EXPECT_GE(valid, supplied.size());
  const auto problem = tree.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;
}

TEST_F(VolumeFixture, ParentBecomesValidWhenAllChildrenAreKnown) {
  ResidencyOctree tree(hierarchy_, OctreeLayout(kExtent, {4, 4, 4}), 1, nothing_resident_);
  const OctreeLayout& layout = tree.layout();
  const std::uint64_t parent = layout.node_index(layout.leaf_depth() - 1, {1, 1, 1});
  const OctreeLayout::Children ch = layout.children(parent);
  RegionMeta all;
  for (std::uint32_t i = 0; i < ch.count; ++i) {
    EXPECT_EQ(state(tree, parent), k::RESOCT_NODE_INVALID);
    const RegionMeta m = truth(layout.node_box(ch.first + i));
    all.merge(m);
    tree.node_metadata(0, ch.first + i, m);
  }
  EXPECT_EQ(state(tree, parent), k::RESOCT_NODE_VALID);
  const std::uint32_t mm = tree.word(parent, 0, k::RESOCT_NODE_MINMAX);
  EXPECT_EQ(k::resoct_node_min16(mm), octree_quantize_min(all.min, ValueRange{0.0, 1.0}));
  EXPECT_EQ(k::resoct_node_max16(mm), octree_quantize_max(all.max, ValueRange{0.0, 1.0}));
  EXPECT_EQ(tree.word(parent, 0, k::RESOCT_NODE_OCCUPANCY), all.occupancy);

  // A narrower answer for the parent itself never narrows it below its children.
  tree.node_metadata(0, parent, RegionMeta{0.5, 0.5, occupancy_bit(0.5, ValueRange{0.0, 1.0})});
  EXPECT_EQ(tree.word(parent, 0, k::RESOCT_NODE_MINMAX), mm);
}

// A source's region answer is conservative but may be much wider than the data (metadata blocks
// coarser than the leaves); once a level-0 brick is resident, its leaves hold the intersection
// with the scan of their sampling support: exactly the data's range, never narrower.
TEST_F(VolumeFixture, Level0BricksTightenWideRegionAnswers) {
  ResidencyOctree tree(hierarchy_, OctreeLayout(kExtent, {4, 4, 4}), 1, nothing_resident_);
  const OctreeLayout& layout = tree.layout();
  const std::uint32_t leaf = layout.leaf_depth();
  const ValueRange r{0.0, 1.0};
  const RegionMeta wide{0.0, 1.0, occupancy_span(0.0, 1.0, r)};
  std::vector<std::uint64_t> leaves;
  for (std::uint64_t node = layout.depth(leaf).first_node; node < layout.node_count(); ++node) {
    if (layout.node_box(node).empty()) continue;
    tree.node_metadata(0, node, wide);
    leaves.push_back(node);
  }
  ASSERT_FALSE(leaves.empty());
  EXPECT_EQ(tree.word(leaves[0], 0, k::RESOCT_NODE_MINMAX), octree_pack_range(0.0, 1.0, r));
  const glm::uvec3 n = hierarchy_.level(0).bricks;
  for (std::uint32_t z = 0; z < n.z; ++z)
    for (std::uint32_t y = 0; y < n.y; ++y)
      for (std::uint32_t x = 0; x < n.x; ++x) {
        tree.metadata_from_brick(0, 0, {x, y, z}, level0_brick({x, y, z}));
      }
  std::size_t tighter = 0;
  for (std::uint64_t node : leaves) {
    ASSERT_EQ(state(tree, node), k::RESOCT_NODE_VALID) << "node " << node;
    expect_valid_bounds(tree, node, /*exact=*/true);
    if (tree.word(node, 0, k::RESOCT_NODE_MINMAX) != octree_pack_range(0.0, 1.0, r)) ++tighter;
  }
  EXPECT_GT(tighter, 0u);  // (exactness per leaf is checked above)
  // A later region answer for a leaf keeps the intersection (it does not widen the record).
  const std::uint32_t before = tree.word(leaves[0], 0, k::RESOCT_NODE_MINMAX);
  tree.node_metadata(0, leaves[0], wide);
  EXPECT_EQ(tree.word(leaves[0], 0, k::RESOCT_NODE_MINMAX), before);
  const auto problem = tree.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;
}

TEST_F(VolumeFixture, CoarseEstimatesAreApproximateAndYieldToFinerData) {
  ResidencyOctree tree(hierarchy_, OctreeLayout(kExtent, {4, 4, 4}), 1, nothing_resident_);
  const OctreeLayout& layout = tree.layout();
  const std::uint32_t top = hierarchy_.level_count() - 1;
  ASSERT_GE(top, 2u);
  auto constant_brick = [&](float v) {
    std::vector<std::byte> out(std::size_t(hierarchy_.layout().padded_voxels()) * 4);
    for (std::size_t i = 0; i < out.size(); i += 4) std::memcpy(out.data() + i, &v, 4);
    return out;
  };
  const ValueRange r{0.0, 1.0};
  tree.metadata_from_brick(0, top, {0, 0, 0}, constant_brick(0.75f));
  EXPECT_EQ(state(tree, 0), k::RESOCT_NODE_APPROX);
  EXPECT_EQ(k::resoct_node_approx_level(tree.word(0, 0, k::RESOCT_NODE_FLAGS)), top);

  // A level-1 estimate replaces the level-`top` one inside its brick; a later coarse one does not.
  tree.metadata_from_brick(0, 1, {0, 0, 0}, constant_brick(0.25f));
  tree.metadata_from_brick(0, top, {0, 0, 0}, constant_brick(0.75f));
  const std::uint64_t leaf0 = layout.node_index(layout.leaf_depth(), {0, 0, 0});
  std::uint64_t n = leaf0;
  while (state(tree, n) == k::RESOCT_NODE_INVALID) n = layout.parent(n);
  EXPECT_EQ(state(tree, n), k::RESOCT_NODE_APPROX);
  EXPECT_EQ(k::resoct_node_approx_level(tree.word(n, 0, k::RESOCT_NODE_FLAGS)), 1u);
  EXPECT_EQ(tree.word(n, 0, k::RESOCT_NODE_MINMAX), octree_pack_range(0.25, 0.25, r));

  // Level-0 data makes the leaves VALID (exact) and their estimates disappear.
  tree.metadata_from_brick(0, 0, {0, 0, 0}, level0_brick({0, 0, 0}));
  EXPECT_EQ(state(tree, leaf0), k::RESOCT_NODE_VALID);
  expect_valid_bounds(tree, leaf0, /*exact=*/true);
  // The root is still only estimated elsewhere, but covers the exact part too.
  EXPECT_EQ(state(tree, 0), k::RESOCT_NODE_APPROX);
  const std::uint32_t root = tree.word(0, 0, k::RESOCT_NODE_MINMAX);
  EXPECT_EQ(k::resoct_node_merge_minmax(root, tree.word(leaf0, 0, k::RESOCT_NODE_MINMAX)), root);
  // Conservative data for the root itself ends the estimate there.
  tree.node_metadata(0, 0, truth(layout.node_box(0)));
  EXPECT_EQ(state(tree, 0), k::RESOCT_NODE_VALID);
  const auto problem = tree.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;
}

// scan_leaves (what the brick loader computes on its threads) against brute force over each
// leaf's sampling support, then stored through leaf_metadata: the same tree as the frame-thread
// scan of metadata_from_brick, whatever order the records arrive in.
TEST_F(VolumeFixture, LeafScansMatchBruteForceAndStoreLikeBrickScans) {
  const OctreeLayout layout(kExtent, {4, 4, 4});
  ResidencyOctree scanned(hierarchy_, layout, 1, nothing_resident_);
  ResidencyOctree stored(hierarchy_, layout, 1, nothing_resident_);
  const ValueRange r{0.0, 1.0};
  std::set<std::uint64_t> seen;
  std::mt19937 rng(5);
  const glm::uvec3 n = hierarchy_.level(0).bricks;
  for (std::uint32_t z = 0; z < n.z; ++z)
    for (std::uint32_t y = 0; y < n.y; ++y)
      for (std::uint32_t x = 0; x < n.x; ++x) {
        const std::vector<std::byte> voxels = level0_brick({x, y, z});
        std::vector<LeafScan> leaves = scan_leaves(layout, hierarchy_, r, {x, y, z}, voxels);
        ASSERT_EQ(leaves.size(), 8u) << "8³ bricks hold 2³ leaves of 4³";
        for (const LeafScan& l : leaves) {
          EXPECT_TRUE(seen.insert(l.leaf).second) << "leaf " << l.leaf << " scanned twice";
          const RegionMeta t = truth(layout.sampling_support(l.leaf));
          EXPECT_EQ(l.minmax, octree_pack_range(t.min, t.max, r)) << "leaf " << l.leaf;
          EXPECT_EQ(l.occupancy, t.occupancy) << "leaf " << l.leaf;
        }
        scanned.metadata_from_brick(0, 0, {x, y, z}, voxels);
        std::shuffle(leaves.begin(), leaves.end(), rng);
        stored.leaf_metadata(0, {x, y, z}, leaves);
      }
  std::size_t in_volume = 0;  // the padded tree's leaves past the far border hold nothing
  for (std::uint64_t l = layout.depth(layout.leaf_depth()).first_node; l < layout.node_count();
       ++l) {
    if (!layout.node_box(l).empty()) ++in_volume;
  }
  EXPECT_EQ(seen.size(), in_volume);
  EXPECT_TRUE(std::equal(scanned.words().begin(), scanned.words().end(), stored.words().begin(),
                         stored.words().end()));
  const auto problem = stored.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;
}

TEST_F(VolumeFixture, LeafMetadataRejectsRecordsOfOtherNodesAndStoresNothing) {
  const OctreeLayout layout(kExtent, {4, 4, 4});
  ResidencyOctree tree(hierarchy_, layout, 1, nothing_resident_);
  const ValueRange r{0.0, 1.0};
  std::vector<LeafScan> leaves =
      scan_leaves(layout, hierarchy_, r, {0, 0, 0}, level0_brick({0, 0, 0}));
  ASSERT_FALSE(leaves.empty());
  const std::vector<std::uint32_t> before(tree.words().begin(), tree.words().end());
  // Leaves of brick (0, 0, 0) handed in as brick (1, 0, 0)'s; the root; an index past the tree.
  EXPECT_RESOCT_ERROR(tree.leaf_metadata(0, {1, 0, 0}, leaves), ErrorCode::out_of_range,
                      "not a leaf of level-0 brick (1, 0, 0)");
  std::vector<LeafScan> root = leaves;
  root.back().leaf = 0;
  EXPECT_RESOCT_ERROR(tree.leaf_metadata(0, {0, 0, 0}, root), ErrorCode::out_of_range, "leaf 0 ");
  std::vector<LeafScan> past = leaves;
  past.front().leaf = layout.node_count();
  EXPECT_RESOCT_ERROR(tree.leaf_metadata(0, {0, 0, 0}, past), ErrorCode::out_of_range,
                      "not a leaf");
  EXPECT_RESOCT_ERROR(tree.leaf_metadata(1, {0, 0, 0}, leaves), ErrorCode::out_of_range, "slot");
  EXPECT_RESOCT_ERROR(tree.leaf_metadata(0, n_bricks_past(), leaves), ErrorCode::out_of_range,
                      "outside level 0");
  EXPECT_TRUE(std::equal(before.begin(), before.end(), tree.words().begin(), tree.words().end()));
  // Leaves of 6³ straddle the bricks' faces: a leaf that only overlaps brick (0, 0, 0) has no
  // record from it (scan_leaves gives none), and one handed in is rejected.
  const OctreeLayout straddling(kExtent, {6, 6, 6});
  ResidencyOctree tree6(hierarchy_, straddling, 1, nothing_resident_);
  const std::uint32_t d6 = straddling.leaf_depth();
  const NodeCoordRange overlap = straddling.node_range(d6, hierarchy_.level0_box(0, glm::uvec3(0)));
  std::vector<LeafScan> partial;
  straddling.for_each_node(d6, overlap, [&](std::uint64_t leaf, glm::uvec3) {
    const Box3 nb = straddling.node_box(d6, straddling.node_coord(leaf));
    if (intersect(nb, hierarchy_.level0_box(0, glm::uvec3(0))) != nb) {
      partial.push_back(LeafScan{leaf, leaves.front().minmax, leaves.front().occupancy});
    }
  });
  ASSERT_FALSE(partial.empty());
  for (const LeafScan& l :
       scan_leaves(straddling, hierarchy_, r, {0, 0, 0}, level0_brick({0, 0, 0}))) {
    for (const LeafScan& p : partial) EXPECT_NE(l.leaf, p.leaf);
  }
  const std::vector<std::uint32_t> before6(tree6.words().begin(), tree6.words().end());
  EXPECT_RESOCT_ERROR(tree6.leaf_metadata(0, {0, 0, 0}, partial), ErrorCode::out_of_range,
                      "whose sampling support the brick holds");
  EXPECT_TRUE(
      std::equal(before6.begin(), before6.end(), tree6.words().begin(), tree6.words().end()));
  // Scans of a brick outside the level, of a wrong buffer, of a brick that is not constant.
  EXPECT_RESOCT_ERROR(scan_leaves(layout, hierarchy_, r, n_bricks_past(), level0_brick({0, 0, 0})),
                      ErrorCode::out_of_range, "outside level 0");
  EXPECT_RESOCT_ERROR(scan_leaves(layout, hierarchy_, r, {0, 0, 0}, std::vector<std::byte>(7)),
                      ErrorCode::invalid_argument, "voxels");
  BrickMeta varied;
  varied.constant = false;
  EXPECT_RESOCT_ERROR(scan_constant_leaves(layout, hierarchy_, r, {0, 0, 0}, varied),
                      ErrorCode::invalid_argument, "meta");
}

TEST_F(VolumeFixture, MetadataSurvivesEviction) {
  bool resident = false;
  ResidencyOctree tree(hierarchy_, OctreeLayout(kExtent, {4, 4, 4}), 1,
                       [&](std::uint32_t, std::uint32_t, glm::uvec3) { return resident; });
  tree.node_metadata(0, 0, truth(tree.layout().node_box(0)));
  const std::vector<std::uint32_t> before(tree.words().begin(), tree.words().end());
  resident = true;
  tree.brick_added(0, 0, {1, 1, 1});
  EXPECT_NE(tree.word(0, 0, k::RESOCT_NODE_RESIDENCY), 0u);
  resident = false;
  tree.brick_evicted(0, 0, {1, 1, 1});
  EXPECT_TRUE(std::equal(before.begin(), before.end(), tree.words().begin()));
}

}  // namespace
}  // namespace resoct
