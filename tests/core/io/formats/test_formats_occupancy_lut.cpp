// The occupancy tables of the level-0 scans (internal io/formats/level0_scan.hpp) against
// occupancy_bit value by value: the table is built from runs found by bisection, which relies on
// the bin never decreasing with the value.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "io/formats/level0_scan.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {
namespace {

void expect_lut_is_occupancy_bit(VoxelType t, const ValueRange& r) {
  const std::vector<std::uint32_t> lut = detail::occupancy_lut(t, r);
  ASSERT_EQ(lut.size(), t == VoxelType::u8 ? 256u : 65536u);
  for (std::size_t v = 0; v < lut.size(); ++v) {
    ASSERT_EQ(lut[v], occupancy_bit(double(v), r))
        << "value " << v << " of range [" << r.lo << ", " << r.hi << "]";
  }
}

TEST(OccupancyLut, EqualsOccupancyBitForEveryValue) {
  for (VoxelType t : {VoxelType::u8, VoxelType::u16}) {
    expect_lut_is_occupancy_bit(t, default_range(t));
    expect_lut_is_occupancy_bit(t, ValueRange{0.0, 1.0});          // everything in the top bin
    expect_lut_is_occupancy_bit(t, ValueRange{100.0, 131.0});      // one value per bin
    expect_lut_is_occupancy_bit(t, ValueRange{-5000.0, 70000.0});  // values inside the range
    expect_lut_is_occupancy_bit(t, ValueRange{3.0, 3.0000001});    // a sliver
    expect_lut_is_occupancy_bit(t, ValueRange{-1e300, 1e300});     // width overflows to inf
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-70000.0, 140000.0);
    for (int i = 0; i < 20; ++i) {
      double a = u(rng), b = u(rng);
      if (a > b) std::swap(a, b);
      if (a == b) continue;
      expect_lut_is_occupancy_bit(t, ValueRange{a, b});
    }
  }
  EXPECT_TRUE(detail::occupancy_lut(VoxelType::f32, ValueRange{0.0, 1.0}).empty());
}

TEST(OccupancyLut, DegenerateRangesAreTabulatedValueByValue) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const ValueRange& r :
       {ValueRange{5.0, 5.0}, ValueRange{9.0, 2.0}, ValueRange{nan, 1.0}, ValueRange{0.0, inf}}) {
    expect_lut_is_occupancy_bit(VoxelType::u8, r);
    expect_lut_is_occupancy_bit(VoxelType::u16, r);
  }
}

}  // namespace
}  // namespace resoct
