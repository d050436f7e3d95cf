#include <gtest/gtest.h>

#include <cmath>

#include "resoct/base/error.hpp"
#include "resoct/volume/hierarchy.hpp"

using namespace resoct;

namespace {
VolumeDesc vol(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  VolumeDesc v;
  v.extent = {x, y, z};
  return v;
}

// Brute-force brick of a level voxel: the definition, not the code under test's shortcut.
std::uint32_t brute_brick(std::uint64_t voxel, std::uint32_t b) {
  return std::uint32_t(voxel / b);
}
}  // namespace

TEST(Hierarchy, AwkwardExtentsEndInOneBrickAndHalveByCeiling) {
  for (std::uint64_t e : {1ull, 31ull, 33ull, 40ull, 795ull, 1023ull}) {
    BrickHierarchy h(vol(e, e, e), BrickLayout{});
    const LevelInfo& last = h.level(h.level_count() - 1);
    EXPECT_EQ(last.brick_count, 1u) << e;
    for (std::uint32_t l = 1; l < h.level_count(); ++l) {
      for (int i = 0; i < 3; ++i) {
        const std::uint64_t f = 1ull << h.level(l).factor_log2[i];
        EXPECT_EQ(h.level(l).extent[i], (e + f - 1) / f) << "extent " << e << " level " << l;
      }
    }
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const LevelInfo& li = h.level(l);
      for (int i = 0; i < 3; ++i) EXPECT_EQ(li.bricks[i], (li.extent[i] + 31) / 32);
    }
  }
  EXPECT_EQ(BrickHierarchy(vol(1, 1, 1), BrickLayout{}).level_count(), 1u);
  EXPECT_EQ(BrickHierarchy(vol(795, 795, 795), BrickLayout{}).level_count(), 6u);  // 25 bricks
}

TEST(Hierarchy, ThinAxisStaysWholeUntilOthersCatchUp) {
  BrickHierarchy h(vol(1024, 1024, 40), BrickLayout{});
  EXPECT_EQ(h.level(1).factor_log2, glm::uvec3(1, 1, 0));
  EXPECT_EQ(h.level(1).extent, glm::u64vec3(512, 512, 40));
  // 64x64x40 is 2x2x1.25 bricks: z is no longer much smaller and halves with the others.
  const std::uint32_t l64 = 4;
  EXPECT_EQ(h.level(l64).extent, glm::u64vec3(64, 64, 40));
  EXPECT_EQ(h.level(l64 + 1).extent, glm::u64vec3(32, 32, 20));
  EXPECT_EQ(h.level_count(), l64 + 2);
}

TEST(Hierarchy, LongAxisOfTwoToTheTwentyVoxels) {
  BrickHierarchy h(vol(1u << 20, 3, 1), BrickLayout{});
  EXPECT_EQ(h.level(0).bricks, glm::uvec3(1u << 15, 1, 1));
  EXPECT_EQ(h.level_count(), 16u);
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    EXPECT_EQ(h.level(l).factor_log2, glm::uvec3(l, 0, 0));
  }
  // The brick of the last voxel at level 0, addressed through a normalized position.
  const double p = (double((1u << 20) - 1) + 0.5) / double(1u << 20);
  EXPECT_EQ(h.brick_at(0, {p, 0.5, 0.5}).x, (1u << 15) - 1u);
}

TEST(Hierarchy, BrickAtMatchesBruteForceForPartialBricks) {
  for (std::uint64_t e : {40ull, 795ull}) {
    BrickHierarchy h(vol(e, 7, 1), BrickLayout{});
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const LevelInfo& li = h.level(l);
      for (std::uint64_t v = 0; v < e; ++v) {
        const double p = (double(v) + 0.5) / double(e);
        const std::uint64_t lv = v >> li.factor_log2.x;
        EXPECT_EQ(h.brick_at(l, {p, 0.5, 0.5}).x, brute_brick(lv, 32)) << e << " " << l << " " << v;
      }
    }
  }
}

TEST(Hierarchy, LinearIndexRoundTripsThroughKeys) {
  BrickHierarchy h(vol(795, 40, 100), BrickLayout{glm::uvec3(16, 16, 8), 2});
  for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i) {
    const BrickKey k = h.key_from_linear(3 % h.volume().channels, i);
    ASSERT_TRUE(h.contains(k));
    EXPECT_EQ(h.linear_index(k.level(), k.brick()), i);
  }
  EXPECT_THROW(h.key_from_linear(0, h.bricks_per_channel()), Error);
}

TEST(Hierarchy, BoxesOfCoreHaloAndLevel0) {
  BrickHierarchy h(vol(40, 40, 40), BrickLayout{glm::uvec3(32), 1});
  EXPECT_EQ(h.core_box(0, {1, 0, 0}), (Box3{{32, 0, 0}, {40, 32, 32}}));
  EXPECT_EQ(h.padded_box(0, {1, 0, 0}), (Box3{{31, -1, -1}, {65, 33, 33}}));
  ASSERT_EQ(h.level_count(), 2u);
  EXPECT_EQ(h.level(1).extent, glm::u64vec3(20));
  EXPECT_EQ(h.level0_box(1, {0, 0, 0}), (Box3{{0, 0, 0}, {40, 40, 40}}));
  EXPECT_EQ(h.level_box_from_level0(1, Box3{{3, 0, 0}, {5, 2, 1}}), (Box3{{1, 0, 0}, {3, 1, 1}}));
}

TEST(Hierarchy, RejectsBadParametersWithNamedErrors) {
  auto expect_error = [](auto&& fn, const char* needle) {
    try {
      fn();
      FAIL() << "no error for " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error([] { BrickHierarchy(vol(0, 4, 4), BrickLayout{}); }, "extent.x");
  expect_error([] { BrickHierarchy(vol(4, 4, 4), BrickLayout{glm::uvec3(3), 1}); }, "brick_size");
  expect_error([] { BrickHierarchy(vol(4, 4, 4), BrickLayout{glm::uvec3(8), 5}); }, "halo");
  expect_error([] { BrickHierarchy(vol(1ull << 40, 1, 1), BrickLayout{}); }, "brick_size");
  expect_error([] { BrickHierarchy(vol(1ull << 32, 1ull << 32, 1ull << 32), BrickLayout{}); },
               "overflow");
  VolumeDesc nan_spacing = vol(4, 4, 4);
  nan_spacing.spacing.y = std::nan("");
  expect_error([&] { BrickHierarchy(nan_spacing, BrickLayout{}); }, "spacing.y");
  VolumeDesc no_channels = vol(4, 4, 4);
  no_channels.channels = 0;
  expect_error([&] { BrickHierarchy(no_channels, BrickLayout{}); }, "channels");
}

TEST(BrickKey, RoundTripsAtTheFieldLimits) {
  for (std::uint32_t level : {0u, 1u, BrickKey::kMaxLevel}) {
    for (std::uint32_t channel : {0u, 7u, BrickKey::kMaxChannel}) {
      for (glm::uvec3 b : {glm::uvec3(0), glm::uvec3(BrickKey::kMaxAxis),
                           glm::uvec3(1, BrickKey::kMaxAxis, 65535)}) {
        const BrickKey k(level, channel, b);
        EXPECT_EQ(k.level(), level);
        EXPECT_EQ(k.channel(), channel);
        EXPECT_EQ(k.brick(), b);
        EXPECT_EQ(BrickKey::from_bits(k.bits()), k);
      }
    }
  }
  EXPECT_GE(BrickKey::kAxisBits, 16u);
  EXPECT_NE(BrickKey(0, 0, {1, 0, 0}), BrickKey(0, 0, {0, 1, 0}));
}
