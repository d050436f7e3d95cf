// Residency octree: randomized add/evict/remap/metadata sequences checked against brute force,
// word deltas, early stop of the upward propagation, and hand-computed cases.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/engine/residency_octree.hpp"
#include "support/expect_error.hpp"

namespace resoct {
namespace {

namespace k = resoct::kernel;

BrickHierarchy make_hierarchy(glm::u64vec3 extent, glm::uvec3 brick, VoxelType type) {
  VolumeDesc v;
  v.extent = extent;
  v.type = type;
  BrickLayout bl;
  bl.brick_size = brick;
  bl.halo = 1;
  return BrickHierarchy(v, bl);
}

// The stand-in for the page table: which (slot, level, brick) are resident.
class ResidentSet {
 public:
  ResidentSet(const BrickHierarchy& h, std::uint32_t slots) : h_(h), flags_(slots) {
    for (auto& f : flags_) f.assign(h.bricks_per_channel(), 0);
  }
  bool contains(std::uint32_t s, std::uint32_t l, glm::uvec3 b) const {
    return flags_[s][h_.linear_index(l, b)] != 0;
  }
  void set(std::uint32_t s, std::uint32_t l, glm::uvec3 b, bool on) {
    flags_[s][h_.linear_index(l, b)] = on ? 1 : 0;
  }
  void clear_slot(std::uint32_t s) { std::fill(flags_[s].begin(), flags_[s].end(), 0); }
  ResidencyQuery query() const {
    return [this](std::uint32_t s, std::uint32_t l, glm::uvec3 b) { return contains(s, l, b); };
  }

 private:
  const BrickHierarchy& h_;
  std::vector<std::vector<std::uint8_t>> flags_;
};

struct RandomCase {
  glm::u64vec3 extent;
  glm::uvec3 brick;
  glm::uvec3 leaf;
  VoxelType type;
  std::uint32_t slots;
  int ops;
};

std::vector<std::byte> random_brick(const BrickHierarchy& h, std::mt19937& rng) {
  const VoxelType t = h.volume().type;
  const std::size_t n = std::size_t(h.layout().padded_voxels());
  std::vector<std::byte> out(n * voxel_size(t));
  std::uniform_int_distribution<int> byte(0, 255);
  // Narrow value ranges per brick so that leaves differ and occupancy is not always full.
  const int base = byte(rng);
  for (std::size_t i = 0; i < n; ++i) {
    const int v = std::min(255, base + byte(rng) % 24);
    if (t == VoxelType::u8) {
      out[i] = std::byte(v);
    } else if (t == VoxelType::u16) {
      const std::uint16_t w = std::uint16_t(v * 257);
      std::memcpy(out.data() + 2 * i, &w, 2);
    } else {
      float f = float(v) / 255.0f;
      if (byte(rng) == 0) f = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(out.data() + 4 * i, &f, 4);
    }
  }
  return out;
}

void run_random_case(const RandomCase& rc, std::uint32_t seed) {
  const BrickHierarchy h = make_hierarchy(rc.extent, rc.brick, rc.type);
  ResidentSet resident(h, rc.slots);
  ResidencyOctree tree(h, OctreeLayout(rc.extent, rc.leaf), rc.slots, resident.query());
  std::vector<std::uint32_t> mirror(tree.words().begin(), tree.words().end());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::tuple<std::uint32_t, std::uint32_t, glm::uvec3>> live;  // resident bricks
  int delta_batches = 0;

  auto random_brick_key = [&](std::uint32_t& slot, std::uint32_t& level, glm::uvec3& b) {
    slot = std::uint32_t(rng() % rc.slots);
    level = unit(rng) < 0.6 ? 0u : std::uint32_t(rng() % h.level_count());
    const glm::uvec3 n = h.level(level).bricks;
    b = {std::uint32_t(rng() % n.x), std::uint32_t(rng() % n.y), std::uint32_t(rng() % n.z)};
  };

  for (int op = 1; op <= rc.ops; ++op) {
    const double r = unit(rng);
    std::uint32_t slot = 0, level = 0;
    glm::uvec3 b{0};
    if (r < 0.40) {
      random_brick_key(slot, level, b);
      if (!resident.contains(slot, level, b)) {
        resident.set(slot, level, b, true);
        live.emplace_back(slot, level, b);
      }
      tree.brick_added(slot, level, b);  // re-adding a resident brick must be harmless
    } else if (r < 0.75) {
      if (live.empty()) continue;
      const std::size_t i = rng() % live.size();
      std::tie(slot, level, b) = live[i];
      live[i] = live.back();
      live.pop_back();
      resident.set(slot, level, b, false);
      tree.brick_evicted(slot, level, b);
    } else if (r < 0.87) {
      slot = std::uint32_t(rng() % rc.slots);
      std::uint64_t node = rng() % tree.layout().node_count();
      while (tree.layout().node_box(node).empty()) node = rng() % tree.layout().node_count();
      const ValueRange vr = tree.slot_range(slot);
      RegionMeta m;
      if (unit(rng) > 0.05) {
        const double a = vr.lo + (vr.hi - vr.lo) * (unit(rng) * 1.2 - 0.1);
        m.min = a;
        m.max = a + (vr.hi - vr.lo) * unit(rng) * 0.3;
        m.occupancy = occupancy_span(m.min, m.max, vr);
      }
      tree.node_metadata(slot, node, m);
    } else if (r < 0.995) {
      random_brick_key(slot, level, b);
      const std::vector<std::byte> vox = random_brick(h, rng);
      tree.metadata_from_brick(slot, level, b, vox);
    } else {
      slot = std::uint32_t(rng() % rc.slots);
      resident.clear_slot(slot);
      std::erase_if(live, [&](const auto& t) { return std::get<0>(t) == slot; });
      const double lo = unit(rng) * 100.0 - 50.0;
      tree.remap_slot(slot, ValueRange{lo, lo + 1.0 + unit(rng) * 300.0});
    }

    if (op % 500 == 0 || op == rc.ops) {
      const auto problem = tree.check_invariants();
      ASSERT_FALSE(problem.has_value()) << "after op " << op << ": " << *problem;
      const OctreeDeltas deltas = tree.take_deltas();
      if (deltas.full) {
        mirror.assign(tree.words().begin(), tree.words().end());
      } else {
        std::vector<std::uint32_t> idx;
        for (const OctreeWordDelta& d : deltas.words) idx.push_back(d.index);
        std::sort(idx.begin(), idx.end());
        ASSERT_TRUE(std::adjacent_find(idx.begin(), idx.end()) == idx.end()) << "duplicates";
        for (const OctreeWordDelta& d : deltas.words) mirror[d.index] = d.value;
        delta_batches += deltas.words.empty() ? 0 : 1;
      }
      ASSERT_TRUE(std::equal(mirror.begin(), mirror.end(), tree.words().begin()))
          << "deltas do not reproduce the words after op " << op;
    }
  }
  EXPECT_GT(delta_batches, 0);
  // Drain: evicting everything must leave no residency bit anywhere.
  for (const auto& [s, l, b] : live) {
    resident.set(s, l, b, false);
    tree.brick_evicted(s, l, b);
  }
  for (std::uint64_t n = 0; n < tree.layout().node_count(); ++n) {
    for (std::uint32_t s = 0; s < rc.slots; ++s) {
      ASSERT_EQ(tree.word(n, s, k::RESOCT_NODE_RESIDENCY), 0u) << "node " << n;
    }
  }
  const auto problem = tree.check_invariants();
  ASSERT_FALSE(problem.has_value()) << *problem;
}

TEST(ResidencyOctree, RandomSequencesIsotropic) {
  run_random_case({{128, 128, 128}, {8, 8, 8}, {4, 4, 4}, VoxelType::u8, 3, 30000}, 1);
}

TEST(ResidencyOctree, RandomSequencesAnisotropic) {
  run_random_case({{256, 256, 24}, {8, 8, 8}, {8, 8, 4}, VoxelType::u16, 2, 30000}, 2);
}

TEST(ResidencyOctree, RandomSequencesAwkwardExtents) {
  run_random_case({{40, 795, 33}, {8, 8, 8}, {4, 16, 8}, VoxelType::f32, 2, 25000}, 3);
}

TEST(ResidencyOctree, RandomSequencesLeavesLargerThanBricks) {
  run_random_case({{96, 64, 40}, {4, 4, 4}, {16, 16, 16}, VoxelType::u8, 2, 20000}, 4);
}

TEST(ResidencyOctree, EvictionKeepsBitWhileAnotherBrickOverlapsTheLeaf) {
  // 32³ volume, 4³ bricks, 16³ leaves: level-0 bricks (0,0,0) and (1,0,0) share leaf (0,0,0).
  const BrickHierarchy h = make_hierarchy({32, 32, 32}, {4, 4, 4}, VoxelType::u8);
  ResidentSet resident(h, 1);
  ResidencyOctree tree(h, OctreeLayout({32, 32, 32}, {16, 16, 16}), 1, resident.query());
  const std::uint64_t leaf = tree.layout().node_index(1, {0, 0, 0});
  const std::uint64_t other_leaf = tree.layout().node_index(1, {1, 0, 0});
  for (const glm::uvec3 b : {glm::uvec3(0, 0, 0), glm::uvec3(1, 0, 0)}) {
    resident.set(0, 0, b, true);
    tree.brick_added(0, 0, b);
  }
  EXPECT_EQ(tree.word(leaf, 0, k::RESOCT_NODE_RESIDENCY), 1u);
  EXPECT_EQ(tree.word(other_leaf, 0, k::RESOCT_NODE_RESIDENCY), 0u);
  EXPECT_EQ(tree.word(0, 0, k::RESOCT_NODE_RESIDENCY), 1u);
  resident.set(0, 0, {0, 0, 0}, false);
  tree.brick_evicted(0, 0, {0, 0, 0});
  EXPECT_EQ(tree.word(leaf, 0, k::RESOCT_NODE_RESIDENCY), 1u);  // (1,0,0) still overlaps
  EXPECT_EQ(tree.word(0, 0, k::RESOCT_NODE_RESIDENCY), 1u);
  resident.set(0, 0, {1, 0, 0}, false);
  tree.brick_evicted(0, 0, {1, 0, 0});
  EXPECT_EQ(tree.word(leaf, 0, k::RESOCT_NODE_RESIDENCY), 0u);
  EXPECT_EQ(tree.word(0, 0, k::RESOCT_NODE_RESIDENCY), 0u);
}

TEST(ResidencyOctree, PropagationStopsAtTheFirstUnchangedDepth) {
  // 512³, 32³ bricks, 16³ leaves: depths 0..5, a level-0 brick covers 2³ leaves exactly.
  const BrickHierarchy h = make_hierarchy({512, 512, 512}, {32, 32, 32}, VoxelType::u8);
  ResidentSet resident(h, 2);
  ResidencyOctree tree(h, OctreeLayout({512, 512, 512}, {16, 16, 16}), 2, resident.query());
  ASSERT_EQ(tree.layout().depth_count(), 6u);

  resident.set(1, 0, {0, 0, 0}, true);
  tree.brick_added(1, 0, {0, 0, 0});
  EXPECT_EQ(tree.stats().words_changed, 8u + 5u);  // 8 leaves and one ancestor per depth
  EXPECT_EQ(tree.stats().nodes_visited, 8u + 5u);

  tree.reset_stats();
  resident.set(1, 0, {1, 0, 0}, true);
  tree.brick_added(1, 0, {1, 0, 0});
  // 8 new leaves, its own 32³ parent; the 64³ grandparent already had the bit: stop there.
  EXPECT_EQ(tree.stats().words_changed, 9u);
  EXPECT_EQ(tree.stats().nodes_visited, 10u);

  tree.reset_stats();
  tree.brick_added(1, 0, {1, 0, 0});  // already covered
  EXPECT_EQ(tree.stats().words_changed, 0u);
  EXPECT_EQ(tree.stats().nodes_visited, 8u);

  tree.reset_stats();
  resident.set(1, 0, {1, 0, 0}, false);
  tree.brick_evicted(1, 0, {1, 0, 0});
  // 8 leaves and the 32³ parent clear; the 64³ node keeps the bit through brick (0,0,0).
  EXPECT_EQ(tree.stats().words_changed, 9u);
  EXPECT_EQ(tree.stats().residency_queries, 0u);  // leaves lie inside the brick
  const auto problem = tree.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;

  const OctreeDeltas d = tree.take_deltas();
  ASSERT_FALSE(d.full);
  // Net change since construction: brick (0,0,0) of slot 1 marked 8 leaves + 5 ancestors.
  std::size_t nonzero = 0;
  for (const auto& w : d.words) nonzero += w.value != 0 ? 1u : 0u;
  EXPECT_EQ(nonzero, 13u);
  EXPECT_EQ(d.words.size(), 13u + 9u);  // the 9 words of brick (1,0,0) went back to 0
  EXPECT_TRUE(tree.take_deltas().words.empty());
}

TEST(ResidencyOctree, CoarseBrickMarksEveryOverlappedNode) {
  const BrickHierarchy h = make_hierarchy({64, 64, 64}, {8, 8, 8}, VoxelType::u8);
  ResidentSet resident(h, 1);
  ResidencyOctree tree(h, OctreeLayout({64, 64, 64}, {8, 8, 8}), 1, resident.query());
  const std::uint32_t top = h.level_count() - 1;
  resident.set(0, top, {0, 0, 0}, true);
  tree.brick_added(0, top, {0, 0, 0});
  for (std::uint64_t n = 0; n < tree.layout().node_count(); ++n) {
    ASSERT_EQ(tree.word(n, 0, k::RESOCT_NODE_RESIDENCY), 1u << top);
  }
  resident.set(0, top, {0, 0, 0}, false);
  tree.brick_evicted(0, top, {0, 0, 0});
  for (std::uint64_t n = 0; n < tree.layout().node_count(); ++n) {
    ASSERT_EQ(tree.word(n, 0, k::RESOCT_NODE_RESIDENCY), 0u);
  }
}

TEST(ResidencyOctree, RemapClearsOnlyThatSlot) {
  const BrickHierarchy h = make_hierarchy({64, 64, 64}, {8, 8, 8}, VoxelType::u16);
  ResidentSet resident(h, 2);
  ResidencyOctree tree(h, OctreeLayout({64, 64, 64}, {8, 8, 8}), 2, resident.query());
  for (std::uint32_t s = 0; s < 2; ++s) {
    resident.set(s, 0, {1, 2, 3}, true);
    tree.brick_added(s, 0, {1, 2, 3});
    tree.node_metadata(s, 0, RegionMeta{10.0, 20.0, 1u});
  }
  resident.clear_slot(1);
  tree.remap_slot(1, ValueRange{0.0, 100.0});
  EXPECT_EQ(tree.slot_range(1), (ValueRange{0.0, 100.0}));
  EXPECT_EQ(tree.word(0, 0, k::RESOCT_NODE_RESIDENCY), 1u);
  EXPECT_EQ(k::resoct_node_state(tree.word(0, 0, k::RESOCT_NODE_FLAGS)), k::RESOCT_NODE_VALID);
  for (std::uint32_t w = 0; w < 4; ++w) EXPECT_EQ(tree.word(0, 1, w), 0u);
  const auto problem = tree.check_invariants();
  EXPECT_FALSE(problem.has_value()) << *problem;
}

TEST(ResidencyOctree, RejectsBadArguments) {
  const BrickHierarchy h = make_hierarchy({64, 64, 64}, {8, 8, 8}, VoxelType::u8);
  ResidentSet resident(h, 1);
  const auto q = resident.query();
  EXPECT_RESOCT_ERROR(ResidencyOctree(h, OctreeLayout({64, 64, 64}, {8, 8, 8}), 0, q),
                      ErrorCode::invalid_argument, "slots");
  EXPECT_RESOCT_ERROR(ResidencyOctree(h, OctreeLayout({64, 64, 32}, {8, 8, 8}), 1, q),
                      ErrorCode::invalid_argument, "layout");
  EXPECT_RESOCT_ERROR(ResidencyOctree(h, OctreeLayout({64, 64, 64}, {8, 8, 8}), 1, nullptr),
                      ErrorCode::invalid_argument, "query");
  const BrickHierarchy big = make_hierarchy({8192, 8192, 8192}, {32, 32, 32}, VoxelType::u8);
  EXPECT_RESOCT_ERROR(ResidencyOctree(big, OctreeLayout({8192, 8192, 8192}, {8, 8, 8}), 64, q),
                      ErrorCode::invalid_argument, "2^32");
  ResidencyOctree tree(h, OctreeLayout({64, 64, 64}, {8, 8, 8}), 1, q);
  EXPECT_RESOCT_ERROR(tree.brick_added(1, 0, {0, 0, 0}), ErrorCode::out_of_range, "slot");
  EXPECT_RESOCT_ERROR(tree.brick_added(0, 9, {0, 0, 0}), ErrorCode::out_of_range, "level");
  EXPECT_RESOCT_ERROR(tree.brick_evicted(0, 0, {8, 0, 0}), ErrorCode::out_of_range, "brick");
  EXPECT_RESOCT_ERROR(tree.node_metadata(0, tree.layout().node_count(), RegionMeta{}),
                      ErrorCode::out_of_range, "node");
  EXPECT_RESOCT_ERROR(tree.remap_slot(0, ValueRange{1.0, 1.0}), ErrorCode::invalid_argument,
                      "range");
  const std::vector<std::byte> short_buf(10);
  EXPECT_RESOCT_ERROR(tree.metadata_from_brick(0, 0, {0, 0, 0}, short_buf),
                      ErrorCode::invalid_argument, "voxels");
  EXPECT_RESOCT_ERROR(tree.metadata_from_constant_brick(0, {0, 0, 0}, BrickMeta{0.1, 0.2, false}),
                      ErrorCode::invalid_argument, "meta");
  EXPECT_RESOCT_ERROR(tree.metadata_from_constant_brick(0, {8, 0, 0}, BrickMeta{0.1, 0.1, true}),
                      ErrorCode::out_of_range, "brick");
}

}  // namespace
}  // namespace resoct
