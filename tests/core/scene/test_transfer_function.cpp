// Transfer functions: exact evaluation, LUT, kernel lookup (kernel/tf.glsl.h as C++), visible
// intervals and occupancy masks, fully transparent and fully opaque edge cases.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/scene/transfer_function.hpp"
#include "resoct/volume/voxel_type.hpp"
#include "support/expect_error.hpp"

namespace resoct::kernel {
// The kernel reads LUTs through this accessor; here over one table per slot.
inline std::vector<std::vector<glm::vec4>> g_luts;
inline glm::vec4 resoct_read_tf(std::uint32_t slot, std::uint32_t index) {
  return g_luts.at(slot).at(index);
}
}  // namespace resoct::kernel

#include "resoct/kernel/tf.glsl.h"

namespace {

using resoct::ErrorCode;
using resoct::TfPoint;
using resoct::TransferFunction;

TransferFunction example() {
  return TransferFunction({{0.0, {0, 0, 0, 0}}, {0.3, {1, 0.5, 0.2, 0.0}}, {1.0, {1, 1, 1, 0.8}}});
}

TEST(TransferFunction, EvaluatesPiecewiseLinear) {
  const TransferFunction tf = example();
  EXPECT_EQ(tf.evaluate(0.0), glm::dvec4(0.0));
  EXPECT_EQ(tf.evaluate(0.15), glm::dvec4(0.5, 0.25, 0.1, 0.0));
  const glm::dvec4 m = tf.evaluate(0.65);  // halfway between 0.3 and 1.0
  EXPECT_DOUBLE_EQ(m.g, 0.75);
  EXPECT_DOUBLE_EQ(m.a, 0.4);
  EXPECT_EQ(tf.evaluate(-3.0), tf.evaluate(0.0));
  EXPECT_EQ(tf.evaluate(7.0), glm::dvec4(1, 1, 1, 0.8));
  EXPECT_EQ(tf.evaluate(std::numeric_limits<double>::infinity()), glm::dvec4(1, 1, 1, 0.8));
  EXPECT_EQ(tf.evaluate(std::nan("")), glm::dvec4(0.0));
}

TEST(TransferFunction, JumpTakesTheRightHandPoint) {
  const TransferFunction tf({{0.5, {0, 0, 0, 0}}, {0.5, {1, 1, 1, 1}}});
  EXPECT_EQ(tf.evaluate(0.4999), glm::dvec4(0.0));
  EXPECT_EQ(tf.evaluate(0.5), glm::dvec4(1.0));
}

TEST(TransferFunction, RejectsInvalidPoints) {
  EXPECT_RESOCT_ERROR(TransferFunction(std::vector<TfPoint>{}), ErrorCode::invalid_argument,
                      "at least one point");
  EXPECT_RESOCT_ERROR(TransferFunction({{0.0, {0, 0, 0, 0}}, {1.3, {0, 0, 0, 0}}}),
                      ErrorCode::invalid_argument, "tf[1]: value 1.3 outside [0,1]");
  EXPECT_RESOCT_ERROR(TransferFunction({{0.5, {0, 0, 0, 0}}, {0.2, {0, 0, 0, 0}}}),
                      ErrorCode::invalid_argument, "tf[1]: value 0.2 below the previous");
  EXPECT_RESOCT_ERROR(TransferFunction({{0.5, {0, 0, 0, 1.5}}}), ErrorCode::invalid_argument,
                      "tf[0]: alpha 1.5 outside [0,1]");
  EXPECT_RESOCT_ERROR(TransferFunction({{0.5, {std::nan(""), 0, 0, 0}}}),
                      ErrorCode::invalid_argument, "tf[0]: red");
}

TEST(TransferFunction, LutEntriesAreExactSamples) {
  const TransferFunction tf = example();
  const std::vector<glm::vec4> lut = tf.lut();
  ASSERT_EQ(lut.size(), resoct::kTfLutSize);
  ASSERT_EQ(resoct::kTfLutSize, resoct::kernel::RESOCT_TF_LUT_SIZE);
  for (std::uint32_t i = 0; i < lut.size(); i += 37) {
    const glm::dvec4 e = tf.evaluate(double(i) / 1023.0);
    for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(lut[i][c], float(e[c]));
  }
  EXPECT_EQ(lut.back(), glm::vec4(1, 1, 1, 0.8f));
}

TEST(TransferFunction, KernelLookupInterpolatesTheLut) {
  using namespace resoct::kernel;
  const TransferFunction tf = example();
  g_luts = {std::vector<glm::vec4>(resoct::kTfLutSize, glm::vec4(0.0f)), tf.lut()};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 500; ++i) {
    const double v = u(rng);
    const vec4 got = resoct_tf_lookup(1u, float(v));
    const glm::dvec4 exact = tf.evaluate(v);
    // Piecewise linear with a kink inside one LUT cell: error at most the kink's effect over
    // one cell (slope change ~ 1.2 per unit value times 1/1023).
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], exact[c], 2e-3);
  }
  EXPECT_EQ(resoct_tf_lookup(1u, -5.0f), vec4(0.0f));
  EXPECT_EQ(resoct_tf_lookup(1u, 5.0f), vec4(1, 1, 1, 0.8f));
  EXPECT_EQ(resoct_tf_lookup(1u, std::nanf("")), vec4(0.0f));
  EXPECT_EQ(resoct_tf_lookup(0u, 0.5f), vec4(0.0f));
  EXPECT_FLOAT_EQ(resoct_normalize_value(1000.0f, 0.0f, 1.0f / 4000.0f), 0.25f);
}

TEST(TransferFunction, VisibleIntervalsAndMask) {
  // Alpha rises from 0 at 0.3: visible from the LUT cell just below 0.3's entry upward.
  const TransferFunction tf = example();
  ASSERT_EQ(tf.visible_intervals().size(), 1u);
  const glm::dvec2 iv = tf.visible_intervals()[0];
  EXPECT_LE(iv.x, 0.3);
  EXPECT_GE(iv.x, 0.3 - 2.0 / 1023.0);
  EXPECT_EQ(iv.y, 1.0);
  // Bins 9 (0.28125..) through 31.
  EXPECT_EQ(tf.visible_mask(), ~0u << 9);
  EXPECT_FALSE(tf.visible_in(0.0, 0.25));
  EXPECT_TRUE(tf.visible_in(0.25, 0.35));
  EXPECT_TRUE(tf.visible_in(1.5, 2.0));  // beyond the range renders like 1.0
  EXPECT_FALSE(tf.visible_in(std::nan(""), 0.5));
  EXPECT_FALSE(tf.visible_in(0.6, 0.5));
}

TEST(TransferFunction, VisibleSetAgreesWithLutBruteForce) {
  // Two separated bumps; every value where the interpolated LUT alpha is > 0 lies in an
  // interval and its occupancy bin is in the mask, and values in no interval render alpha 0.
  using namespace resoct::kernel;
  const TransferFunction tf({{0.1, {1, 0, 0, 0}},
                             {0.2, {1, 0, 0, 0.5}},
                             {0.25, {1, 0, 0, 0}},
                             {0.7, {0, 1, 0, 0}},
                             {0.71, {0, 1, 0, 1}},
                             {0.72, {0, 1, 0, 0}}});
  ASSERT_EQ(tf.visible_intervals().size(), 2u);
  g_luts = {tf.lut()};
  const resoct::ValueRange unit{0.0, 1.0};
  for (int i = 0; i <= 100000; ++i) {
    const double v = i / 100000.0;
    const bool rendered = resoct_tf_lookup(0u, float(v)).a > 0.0f;
    bool listed = false;
    for (const glm::dvec2& iv : tf.visible_intervals()) listed = listed || (v >= iv.x && v <= iv.y);
    if (rendered) {
      EXPECT_TRUE(listed) << v;
      EXPECT_NE(tf.visible_mask() & resoct::occupancy_bit(v, unit), 0u) << v;
      EXPECT_TRUE(tf.visible_in(v, v)) << v;
    }
  }
  // Far from both bumps nothing is visible.
  EXPECT_FALSE(tf.visible_in(0.3, 0.65));
  EXPECT_TRUE(tf.visible_in(0.3, 0.705));
}

TEST(TransferFunction, KernelRangeTestIsConservative) {
  // For random node bounds: whenever the exact interval test says visible, the kernel's
  // bin-mask test must too; and the kernel test agrees with the host occupancy mask.
  using namespace resoct::kernel;
  const TransferFunction tf({{0.1, {1, 0, 0, 0}},
                             {0.2, {1, 0, 0, 0.5}},
                             {0.25, {1, 0, 0, 0}},
                             {0.7, {0, 1, 0, 0}},
                             {0.71, {0, 1, 0, 1}},
                             {0.72, {0, 1, 0, 0}}});
  const resoct::ValueRange unit{0.0, 1.0};
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  for (int i = 0; i < 20000; ++i) {
    double lo = u(rng), hi = u(rng);
    if (lo > hi) std::swap(lo, hi);
    const bool kernel = resoct_tf_range_visible(tf.visible_mask(), float(lo), float(hi));
    if (tf.visible_in(lo, hi)) {
      EXPECT_TRUE(kernel) << lo << " " << hi;
    }
    EXPECT_EQ(kernel, (tf.visible_mask() & resoct::occupancy_span(lo, hi, unit)) != 0u);
  }
  EXPECT_FALSE(resoct_tf_range_visible(~0u, std::nanf(""), 1.0f));
  EXPECT_FALSE(resoct_tf_range_visible(~0u, 0.6f, 0.5f));
  EXPECT_EQ(resoct_occupancy_bin(1.0f), 31u);
  EXPECT_EQ(resoct_occupancy_bin(0.03125f), 1u);
  EXPECT_EQ(resoct_occupancy_bin(-4.0f), 0u);
}

TEST(TransferFunction, FullyTransparentAndFullyOpaque) {
  const TransferFunction none({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0}}});
  EXPECT_TRUE(none.fully_transparent());
  EXPECT_EQ(none.visible_mask(), 0u);
  EXPECT_FALSE(none.visible_in(0.0, 1.0));
  EXPECT_TRUE(TransferFunction().fully_transparent());

  const TransferFunction all({{0.5, {1, 1, 1, 1}}});
  EXPECT_FALSE(all.fully_transparent());
  EXPECT_EQ(all.visible_mask(), ~0u);
  ASSERT_EQ(all.visible_intervals().size(), 1u);
  EXPECT_EQ(all.visible_intervals()[0], glm::dvec2(0.0, 1.0));
  EXPECT_TRUE(all.visible_in(0.0, 0.0));
  EXPECT_TRUE(all.visible_in(-1.0, -0.5));
}

}  // namespace
