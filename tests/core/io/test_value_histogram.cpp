// Percentiles from the data (docs/viewer.md, docs/renderer.md "resoct-render"): without an OMERO
// window, overview_hints takes a histogram of the coarsest pyramid level, and the overview's ramp
// spans its 50th to 99.5th percentile. Volumes whose percentiles are known analytically.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "resoct/io/overview_hints.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/sources/value_histogram.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

// 16^3 u16 voxels, value x + 16 y + 256 z: every value 0..4095 once. One 16^3 brick covers the
// volume, so the coarsest level is level 0 itself.
std::shared_ptr<const BrickSource> uniform_4096(ValueRange range) {
  VolumeDesc d;
  d.extent = glm::u64vec3(16);
  d.type = VoxelType::u16;
  d.ranges = {range};
  std::vector<std::uint16_t> v(4096);
  for (std::uint32_t i = 0; i < 4096; ++i) v[i] = std::uint16_t(i);
  return std::make_shared<InMemorySource>(DenseVolume::from_values(d, v),
                                          BrickLayout{glm::uvec3(16), 1});
}

TEST(ValueHistogram, UniformValuesGiveTheirAnalyticPercentiles) {
  const auto src = uniform_4096(ValueRange{0.0, 4096.0});
  const std::vector<std::uint64_t> h = coarse_value_histogram(*src, 0, 1024);
  ASSERT_EQ(h.size(), 1024u);
  for (std::uint64_t c : h) ASSERT_EQ(c, 4u);  // 4 values per bin of width 4
  // Uniform over [0, 4096): the p-th percentile is 4096 p / 100 (normalized p / 100).
  EXPECT_NEAR(*histogram_percentile(h, 50.0), 0.5, 1e-9);
  EXPECT_NEAR(*histogram_percentile(h, 99.5), 0.995, 1e-9);

  // overview_hints computes it when no window exists, and the overview's ramp spans it: opacity
  // 0 up to the median (2048 of 4096), 0.5 from the 99.5th percentile (4075.5) on.
  const OverviewHints hints = overview_hints(*src);
  ASSERT_EQ(hints.channels.size(), 1u);
  EXPECT_EQ(hints.channels[0].histogram, h);
  const Scene s = overview_scene(src->volume(), Viewport{32, 32}, hints);
  const TransferFunction& tf = s.channels.at(0).tf;
  EXPECT_EQ(tf.evaluate(0.49).a, 0.0);
  EXPECT_GT(tf.evaluate(0.52).a, 0.0);
  EXPECT_LT(tf.evaluate(0.98).a, 0.5);
  EXPECT_NEAR(tf.evaluate(0.999).a, 0.5, 1e-9);
}

TEST(ValueHistogram, ReadsTheCoarsestLevelOnly) {
  // 64^3 u8 ramp along x (value = x), bricks of 16: the coarsest level is one brick of 16^3
  // voxels, each the mean of 4 consecutive x values: 1.5, 5.5, ..., 61.5, equally often.
  VolumeDesc d;
  d.extent = glm::u64vec3(64);
  d.type = VoxelType::u8;
  d.ranges = {ValueRange{0.0, 64.0}};
  std::vector<std::uint8_t> v(64 * 64 * 64);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::uint8_t(i % 64);
  InMemorySource src(DenseVolume::from_values(d, v), BrickLayout{glm::uvec3(16), 1});
  ASSERT_EQ(src.hierarchy().level_count(), 3u);
  const std::vector<std::uint64_t> h = coarse_value_histogram(src, 0, 64);
  std::uint64_t total = 0;
  std::uint32_t occupied = 0;
  for (std::uint32_t b = 0; b < 64; ++b) {
    total += h[b];
    if (h[b] == 0) continue;
    ++occupied;
    // Averages of u8 voxels are stored as integers: 1.5 becomes 1 or 2, so each group of four
    // values gives one bin, 1 or 2 above the group's start.
    EXPECT_TRUE(b % 4 == 1 || b % 4 == 2) << b;
  }
  EXPECT_EQ(occupied, 16u);
  EXPECT_EQ(total, 16u * 16u * 16u);  // the coarsest level's voxels, each once
  // The median of 16 equally frequent values 1.5 .. 61.5 lies between the 8th and the 9th.
  const double median = *histogram_percentile(h, 50.0) * 64.0;
  EXPECT_GT(median, 29.0);
  EXPECT_LT(median, 35.0);
}

TEST(ValueHistogram, BadArgumentsAreNamed) {
  const auto src = uniform_4096(ValueRange{0.0, 4096.0});
  EXPECT_RESOCT_ERROR(coarse_value_histogram(*src, 1, 16), ErrorCode::invalid_argument, "channel");
  EXPECT_RESOCT_ERROR(coarse_value_histogram(*src, 0, 0), ErrorCode::invalid_argument, "bins");
}

}  // namespace
}  // namespace resoct::test
