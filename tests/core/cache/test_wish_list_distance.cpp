// The Octreemizer's neighbourhood distance (WishListDistance): the wish list tree holds the wished
// bricks and all their ancestors, distances are Chebyshev distances in bricks of the key's own
// level and channel, checked against a brute-force definition on anisotropic hierarchies.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <random>
#include <set>
#include <vector>

#include "resoct/cache/eviction_policy.hpp"
#include "resoct/cache/wish_list_distance.hpp"
#include "resoct/engine/brick_cache.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

BrickHierarchy hierarchy(glm::u64vec3 extent, std::uint32_t channels, std::uint32_t brick) {
  VolumeDesc v;
  v.extent = extent;
  v.channels = channels;
  return BrickHierarchy(v, BrickLayout{glm::uvec3(brick), 1});
}

bool box_inside(const Box3& inner, const Box3& outer) {
  return glm::all(glm::greaterThanEqual(inner.lo, outer.lo)) &&
         glm::all(glm::lessThanEqual(inner.hi, outer.hi));
}

// The tree by definition: a brick is in it when it is wished or its level-0 footprint contains
// that of a wished brick of the same channel (an ancestor), found by search over every brick.
std::set<BrickKey> brute_tree(const BrickHierarchy& h, const std::vector<BrickKey>& wish) {
  std::set<BrickKey> tree(wish.begin(), wish.end());
  for (const BrickKey w : wish) {
    const Box3 child = h.level0_box(w.level(), w.brick());
    for (std::uint32_t l = w.level() + 1; l < h.level_count(); ++l) {
      const glm::uvec3 n = h.level(l).bricks;
      for (std::uint32_t z = 0; z < n.z; ++z)
        for (std::uint32_t y = 0; y < n.y; ++y)
          for (std::uint32_t x = 0; x < n.x; ++x) {
            if (box_inside(child, h.level0_box(l, {x, y, z}))) {
              tree.insert(BrickKey(l, w.channel(), {x, y, z}));
            }
          }
    }
  }
  return tree;
}

std::uint32_t brute_distance(const std::set<BrickKey>& tree, BrickKey k) {
  std::uint32_t best = WishListDistance::kFar;
  for (const BrickKey t : tree) {
    if (t.level() != k.level() || t.channel() != k.channel()) continue;
    const glm::ivec3 d = glm::abs(glm::ivec3(t.brick()) - glm::ivec3(k.brick()));
    best = std::min(best, std::uint32_t(std::max({d.x, d.y, d.z})));
  }
  return best;
}

}  // namespace

TEST(WishListDistance, NeighbourhoodShellsAroundOneWishedBrick) {
  // 256^3, 32^3 bricks: levels of 8^3, 4^3, 2^3 and 1 bricks.
  const BrickHierarchy h = hierarchy(glm::u64vec3(256), 2, 32);
  ASSERT_EQ(h.level_count(), 4u);
  WishListDistance d(h);
  EXPECT_EQ(d.distance(BrickKey(0, 0, {5, 5, 5})), WishListDistance::kFar);  // empty list
  const std::vector<BrickKey> wish{BrickKey(0, 0, {5, 5, 5})};
  d.assign(wish);
  EXPECT_EQ(d.tree_size(), 4u);  // the brick and its three ancestors
  EXPECT_EQ(d.distance(BrickKey(0, 0, {5, 5, 5})), 0u);
  EXPECT_EQ(d.distance(BrickKey(1, 0, {2, 2, 2})), 0u);
  EXPECT_EQ(d.distance(BrickKey(2, 0, {1, 1, 1})), 0u);
  EXPECT_EQ(d.distance(BrickKey(3, 0, {0, 0, 0})), 0u);
  EXPECT_EQ(d.distance(BrickKey(0, 0, {6, 6, 6})), 1u);  // one of the 26 neighbours
  EXPECT_EQ(d.distance(BrickKey(0, 0, {4, 5, 6})), 1u);
  EXPECT_EQ(d.distance(BrickKey(0, 0, {7, 5, 3})), 2u);  // one of the 98 at distance two
  EXPECT_EQ(d.distance(BrickKey(0, 0, {0, 0, 0})), 5u);
  EXPECT_EQ(d.distance(BrickKey(1, 0, {0, 3, 0})), 2u);  // measured in level-1 bricks
  EXPECT_EQ(d.distance(BrickKey(2, 0, {0, 0, 0})), 1u);
  // Another channel has no tree.
  EXPECT_EQ(d.distance(BrickKey(0, 1, {5, 5, 5})), WishListDistance::kFar);
  // Count the shells: 26 bricks at distance one, 98 at two (inside the 8^3 grid).
  std::uint32_t one = 0, two = 0;
  for (std::uint32_t z = 0; z < 8; ++z)
    for (std::uint32_t y = 0; y < 8; ++y)
      for (std::uint32_t x = 0; x < 8; ++x) {
        const std::uint32_t v = d.distance(BrickKey(0, 0, {x, y, z}));
        one += v == 1 ? 1 : 0;
        two += v == 2 ? 1 : 0;
      }
  EXPECT_EQ(one, 26u);
  EXPECT_EQ(two, 98u);
}

TEST(WishListDistance, MatchesTheBruteForceDefinition) {
  std::mt19937 gen(7);
  // Anisotropic: the coarser levels halve the long axes first, so parents differ per axis.
  for (const auto& [extent, brick] : std::vector<std::pair<glm::u64vec3, std::uint32_t>>{
           {{200, 120, 40}, 16}, {{64, 64, 64}, 8}, {{300, 20, 90}, 16}}) {
    const BrickHierarchy h = hierarchy(extent, 3, brick);
    for (int round = 0; round < 4; ++round) {
      std::vector<BrickKey> wish;
      const int count = 1 + int(gen() % 12);
      for (int i = 0; i < count; ++i) {
        const std::uint32_t l = std::uint32_t(gen() % h.level_count());
        const glm::uvec3 n = h.level(l).bricks;
        wish.push_back(BrickKey(
            l, std::uint32_t(gen() % 2),
            {std::uint32_t(gen() % n.x), std::uint32_t(gen() % n.y), std::uint32_t(gen() % n.z)}));
      }
      WishListDistance d(h);
      d.assign(wish);
      const std::set<BrickKey> tree = brute_tree(h, wish);
      ASSERT_EQ(d.tree_size(), tree.size());
      for (std::uint32_t c = 0; c < 3; ++c) {
        for (std::uint32_t l = 0; l < h.level_count(); ++l) {
          const glm::uvec3 n = h.level(l).bricks;
          for (std::uint32_t z = 0; z < n.z; ++z)
            for (std::uint32_t y = 0; y < n.y; ++y)
              for (std::uint32_t x = 0; x < n.x; ++x) {
                const BrickKey k(l, c, {x, y, z});
                ASSERT_EQ(d.distance(k), brute_distance(tree, k))
                    << "level " << l << " channel " << c << " brick " << x << "," << y << "," << z;
              }
        }
      }
    }
  }
}

TEST(WishListDistance, KeysOutsideTheHierarchyAreRejectedAndTheListKept) {
  const BrickHierarchy h = hierarchy(glm::u64vec3(64), 1, 16);
  WishListDistance d(h);
  d.assign(std::vector<BrickKey>{BrickKey(0, 0, {1, 1, 1})});
  EXPECT_RESOCT_ERROR(d.assign(std::vector<BrickKey>{BrickKey(0, 0, {4, 0, 0})}),
                      ErrorCode::out_of_range, "wish list");
  EXPECT_RESOCT_ERROR(d.assign(std::vector<BrickKey>{BrickKey(0, 1, {0, 0, 0})}),
                      ErrorCode::out_of_range, "channel 1");
  EXPECT_RESOCT_ERROR(d.assign(std::vector<BrickKey>{BrickKey(9, 0, {0, 0, 0})}),
                      ErrorCode::out_of_range, "level 9");
  EXPECT_EQ(d.distance(BrickKey(0, 0, {1, 1, 1})), 0u);
  EXPECT_EQ(d.distance(BrickKey(0, 0, {3, 1, 0})), 2u);
}

// The published Octreemizer priority end to end: with equal age and level, the brick farthest
// from the wish list tree goes first, and a new wish list (distances_changed) reorders at once.
TEST(WishListDistance, OctreemizerEvictsTheBrickFarthestFromTheWishList) {
  const BrickHierarchy h = hierarchy(glm::u64vec3(256), 1, 32);  // 8^3 bricks at level 0
  auto wish = std::make_shared<WishListDistance>(h);
  auto policy = std::make_unique<OctreemizerPolicy>(
      h.level_count(), OctreemizerWeights{},
      [&wish](BrickKey k) { return double(wish->distance(k)); });
  BrickCache cache(h.layout(), VoxelType::u8, h.layout().padded_voxels() * 3, 0, std::move(policy));
  cache.begin_frame(1);
  for (const std::uint32_t x : {0u, 3u, 7u}) ASSERT_TRUE(cache.insert(BrickKey(0, 0, {x, 0, 0})));
  // Wished: x = 0. Distances 0, 3, 7: the brick at x = 7 is evicted first.
  cache.begin_frame(2);
  wish->assign(std::vector<BrickKey>{BrickKey(0, 0, {0, 0, 0})});
  cache.policy().distances_changed();
  auto ins = cache.insert(BrickKey(0, 0, {1, 1, 1}));
  ASSERT_TRUE(ins && ins->evicted);
  EXPECT_EQ(*ins->evicted, BrickKey(0, 0, {7, 0, 0}));
  // The wish list moves to x = 7. p = age + d: x = 0 has 2 + 7, x = 3 has 2 + 4, and {1, 1, 1},
  // inserted a frame later, 1 + 6: x = 0 goes.
  cache.begin_frame(3);
  wish->assign(std::vector<BrickKey>{BrickKey(0, 0, {7, 0, 0})});
  cache.policy().distances_changed();
  ins = cache.insert(BrickKey(0, 0, {6, 0, 0}));
  ASSERT_TRUE(ins && ins->evicted);
  EXPECT_EQ(*ins->evicted, BrickKey(0, 0, {0, 0, 0}));
}
