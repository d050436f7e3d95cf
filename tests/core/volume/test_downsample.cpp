#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "resoct/volume/downsample.hpp"
#include "resoct/base/error.hpp"
#include "support/expect_error.hpp"
#include "support/reference_levels.hpp"

using namespace resoct;

namespace {

template <typename T>
std::vector<std::byte> to_bytes(const std::vector<T>& v) {
  std::vector<std::byte> b(v.size() * sizeof(T));
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

template <typename T>
std::vector<T> from_bytes(const std::vector<std::byte>& b) {
  std::vector<T> v(b.size() / sizeof(T));
  std::memcpy(v.data(), b.data(), b.size());
  return v;
}

template <typename T>
std::vector<T> run(const std::vector<T>& in, glm::u64vec3 e, glm::bvec3 halve, VoxelType t) {
  const glm::u64vec3 ce = downsampled_extent(e, halve);
  std::vector<std::byte> out(ce.x * ce.y * ce.z * sizeof(T));
  downsample(to_bytes(in), e, halve, t, out);
  return from_bytes<T>(out);
}

// The definition: coarse voxel c averages every fine voxel p with p >> halve == c.
double brute(const std::vector<double>& in, glm::u64vec3 e, glm::bvec3 halve, glm::u64vec3 c,
             VoxelType t) {
  double sum = 0.0;
  int n = 0;
  for (std::uint64_t z = 0; z < e.z; ++z)
    for (std::uint64_t y = 0; y < e.y; ++y)
      for (std::uint64_t x = 0; x < e.x; ++x) {
        const glm::u64vec3 p{x, y, z};
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside &= (halve[a] ? p[a] / 2 : p[a]) == c[a];
        const double v = in[std::size_t((z * e.y + y) * e.x + x)];
        if (!inside || std::isnan(v)) continue;
        sum += v;
        ++n;
      }
  if (t == VoxelType::f32) return n ? double(float(sum / n)) : std::nan("");
  return double((std::uint64_t(sum) + std::uint64_t(n / 2)) / std::uint64_t(n));
}

template <typename T>
void check_against_brute(VoxelType t, double maxv) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> dist(0.0, maxv);
  const glm::u64vec3 extents[] = {{5, 7, 3}, {1, 1, 1}, {4, 4, 4}, {9, 2, 1}, {3, 5, 6}};
  for (const glm::u64vec3& e : extents) {
    std::vector<T> in(std::size_t(e.x * e.y * e.z));
    std::vector<double> ind(in.size());
    for (std::size_t i = 0; i < in.size(); ++i) {
      in[i] = T(t == VoxelType::f32 ? dist(rng) : std::floor(dist(rng)));
      ind[i] = double(in[i]);
    }
    for (int mask = 0; mask < 8; ++mask) {
      const glm::bvec3 halve{(mask & 1) != 0, (mask & 2) != 0, (mask & 4) != 0};
      const glm::u64vec3 ce = downsampled_extent(e, halve);
      for (int a = 0; a < 3; ++a) EXPECT_EQ(ce[a], halve[a] ? (e[a] + 1) / 2 : e[a]);
      const std::vector<T> out = run(in, e, halve, t);
      for (std::uint64_t z = 0; z < ce.z; ++z)
        for (std::uint64_t y = 0; y < ce.y; ++y)
          for (std::uint64_t x = 0; x < ce.x; ++x) {
            const double want = brute(ind, e, halve, {x, y, z}, t);
            ASSERT_EQ(double(out[std::size_t((z * ce.y + y) * ce.x + x)]), want)
                << "type " << to_string(t) << " mask " << mask << " at " << x << "," << y << ","
                << z;
          }
    }
  }
}

}  // namespace

TEST(Downsample, OddExtentsAndAllAxisSubsetsMatchTheDefinition) {
  check_against_brute<std::uint8_t>(VoxelType::u8, 256.0);
  check_against_brute<std::uint16_t>(VoxelType::u16, 65536.0);
  check_against_brute<float>(VoxelType::f32, 1000.0);
}

TEST(Downsample, IntegerMeansRoundHalfUp) {
  // 2 voxels: 1,2 -> 1.5 -> 2; 4 voxels 1,1,1,2 -> 1.25 -> 1; 1,2,2,2 -> 1.75 -> 2.
  EXPECT_EQ(run<std::uint8_t>({1, 2}, {2, 1, 1}, {true, false, false}, VoxelType::u8),
            (std::vector<std::uint8_t>{2}));
  EXPECT_EQ(run<std::uint8_t>({1, 1, 1, 2}, {2, 2, 1}, {true, true, false}, VoxelType::u8),
            (std::vector<std::uint8_t>{1}));
  EXPECT_EQ(run<std::uint8_t>({1, 2, 2, 2}, {2, 2, 1}, {true, true, false}, VoxelType::u8),
            (std::vector<std::uint8_t>{2}));
  EXPECT_EQ(run<std::uint8_t>({255, 254}, {2, 1, 1}, {true, false, false}, VoxelType::u8),
            (std::vector<std::uint8_t>{255}));
  // 8 voxels near the top of the range: mean 65534.25 rounds down, and the sum does not wrap.
  EXPECT_EQ(run<std::uint16_t>({65535, 65535, 65535, 65535, 65534, 65534, 65533, 65533}, {2, 2, 2},
                               {true, true, true}, VoxelType::u16),
            (std::vector<std::uint16_t>{65534}));
  // Odd axis: the last coarse voxel is the lone fine voxel, not half of it.
  EXPECT_EQ(run<std::uint8_t>({10, 20, 31}, {3, 1, 1}, {true, false, false}, VoxelType::u8),
            (std::vector<std::uint8_t>{15, 31}));
}

TEST(Downsample, NaNIsExcludedAndInfinitiesFollowIEEE) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  auto one = [&](std::vector<float> v) {
    return run<float>(v, {2, 2, 1}, {true, true, false}, VoxelType::f32).at(0);
  };
  EXPECT_EQ(one({nan, 3.0f, nan, 5.0f}), 4.0f);
  EXPECT_EQ(one({nan, nan, nan, 7.0f}), 7.0f);
  EXPECT_TRUE(std::isnan(one({nan, nan, nan, nan})));
  EXPECT_EQ(one({inf, 1.0f, 2.0f, nan}), inf);
  EXPECT_EQ(one({-inf, 1.0f, nan, nan}), -inf);
  EXPECT_TRUE(std::isnan(one({inf, -inf, 1.0f, 1.0f})));
  // A NaN neighbour does not spread to the next coarse voxel along an odd axis.
  const std::vector<float> row =
      run<float>({nan, nan, 1.0f}, {3, 1, 1}, {true, false, false}, VoxelType::f32);
  EXPECT_TRUE(std::isnan(row[0]));
  EXPECT_EQ(row[1], 1.0f);
}

TEST(Downsample, TwoByTwoByOneKeepsZ) {
  std::vector<std::uint8_t> in(4 * 4 * 3);
  for (std::size_t i = 0; i < in.size(); ++i) in[i] = std::uint8_t(i);
  const std::vector<std::uint8_t> out = run(in, {4, 4, 3}, {true, true, false}, VoxelType::u8);
  ASSERT_EQ(out.size(), 2u * 2u * 3u);
  for (std::uint64_t z = 0; z < 3; ++z)
    for (std::uint64_t y = 0; y < 2; ++y)
      for (std::uint64_t x = 0; x < 2; ++x) {
        unsigned sum = 0;
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) sum += in[(z * 4 + 2 * y + dy) * 4 + 2 * x + dx];
        EXPECT_EQ(out[(z * 2 + y) * 2 + x], (sum + 2) / 4);
      }
}

TEST(Downsample, RegionAndLevelsEqualWholeLevelDownsampling) {
  VolumeDesc d;
  d.extent = {37, 21, 11};
  d.type = VoxelType::u16;
  BrickHierarchy h(d, BrickLayout{glm::uvec3(4), 1});
  ASSERT_GE(h.level_count(), 4u);
  std::mt19937 rng(7);
  std::vector<double> l0(std::size_t(d.voxel_count()));
  for (double& v : l0) v = double(rng() % 65536);
  const std::vector<test::RefLevel> ref = test::reference_levels(h, l0, d.type);
  std::vector<std::byte> l0_bytes(l0.size() * 2);
  for (std::size_t i = 0; i < l0.size(); ++i) {
    const std::uint16_t v = std::uint16_t(l0[i]);
    std::memcpy(l0_bytes.data() + 2 * i, &v, 2);
  }
  int reads = 0;
  const VoxelBoxReader read0 = [&](const Box3& b, std::span<std::byte> out) {
    ++reads;
    ASSERT_EQ(out.size(), std::size_t(b.volume()) * 2);
    std::size_t o = 0;
    for (std::int64_t z = b.lo.z; z < b.hi.z; ++z)
      for (std::int64_t y = b.lo.y; y < b.hi.y; ++y)
        for (std::int64_t x = b.lo.x; x < b.hi.x; ++x, o += 2)
          std::memcpy(out.data() + o,
                      l0_bytes.data() + 2 * std::size_t((z * d.extent.y + y) * d.extent.x + x), 2);
  };
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const glm::i64vec3 e(h.level(l).extent);
    for (int trial = 0; trial < 20; ++trial) {
      Box3 b;
      for (int a = 0; a < 3; ++a) {
        b.lo[a] = std::int64_t(rng() % std::uint64_t(e[a]));
        b.hi[a] = b.lo[a] + 1 + std::int64_t(rng() % std::uint64_t(e[a] - b.lo[a]));
      }
      std::vector<std::byte> out(std::size_t(b.volume()) * 2);
      downsample_levels(h, 0, l, b, read0, out);
      std::size_t i = 0;
      for (std::int64_t z = b.lo.z; z < b.hi.z; ++z)
        for (std::int64_t y = b.lo.y; y < b.hi.y; ++y)
          for (std::int64_t x = b.lo.x; x < b.hi.x; ++x, ++i)
            ASSERT_EQ(test::voxel_as_double(out.data(), i, d.type), ref[l].at(x, y, z))
                << "level " << l << " voxel " << x << "," << y << "," << z;
    }
  }
  EXPECT_GT(reads, 0);
}

TEST(Downsample, RejectsBadBuffersAndBoxes) {
  std::vector<std::byte> in(10), out(5);
  EXPECT_RESOCT_ERROR(downsample(in, {11, 1, 1}, {true, false, false}, VoxelType::u8, out),
                      ErrorCode::invalid_argument, "fine");
  EXPECT_RESOCT_ERROR(downsample(in, {10, 1, 1}, {true, false, false}, VoxelType::u16, out),
                      ErrorCode::invalid_argument, "fine");
  std::vector<std::byte> small(4);
  EXPECT_RESOCT_ERROR(downsample(in, {10, 1, 1}, {true, false, false}, VoxelType::u8, small),
                      ErrorCode::invalid_argument, "out");
  const VoxelBoxReader never = [](const Box3&, std::span<std::byte>) { FAIL(); };
  EXPECT_RESOCT_ERROR(downsample_region(Box3{{3, 0, 0}, {6, 1, 1}}, {10, 1, 1},
                                        {true, false, false}, VoxelType::u8, never, out),
                      ErrorCode::invalid_argument, "coarse_box");
  VolumeDesc d;
  d.extent = {16, 16, 16};
  BrickHierarchy h(d, BrickLayout{glm::uvec3(4), 0});
  EXPECT_RESOCT_ERROR(downsample_levels(h, 2, 1, Box3{{0, 0, 0}, {1, 1, 1}}, never, out),
                      ErrorCode::invalid_argument, "to");
  EXPECT_RESOCT_ERROR(
      downsample_levels(h, 0, h.level_count(), Box3{{0, 0, 0}, {1, 1, 1}}, never, out),
      ErrorCode::invalid_argument, "to");
}
