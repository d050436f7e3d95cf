// Step levels and their opacity-corrected LUTs (scene/step_lut.hpp, kernel/step_lut.glsl.h):
// every ray a frame can cast has a level, the level rounds the kernel's step down by at most one
// level spacing, and a level's LUT is the per-sample correction of its entries.
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/base/error.hpp"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/scene/step_lut.hpp"

namespace resoct::kernel {
// The accessors of the headers below: step_lut.glsl.h's LUT entry i is (i, i, i, i); the
// transfer-function LUT and level sizes are not used here.
inline vec4 resoct_read_step_lut(uint index) {
  const float v = float(index);
  return vec4(v, v, v, v);
}
inline vec4 resoct_read_tf(uint, uint) {
  return vec4(0.0f);
}
inline float resoct_read_level_size_log2(uint) {
  return 0.0f;
}
}  // namespace resoct::kernel

#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/step_lut.glsl.h"

namespace resoct::test {
namespace {

namespace k = resoct::kernel;

k::ResoctFrame frame_of(const StepLevels& levels) {
  k::ResoctFrame f{};
  f.step_level_shift = levels.shift;
  f.step_level_first = levels.first;
  f.step_level_count = levels.count;
  return f;
}

// For many random unit directions (axis-aligned and near-parallel ones included), the kernel's
// step has a level, the level's ratio is at most the step's ratio and at least 1/(1 + 2^-bits)
// of it, where bits = 23 - shift.
void expect_every_direction_has_a_level(glm::dvec3 h, double scale, const char* what) {
  const float ref = float(std::min(h.x, std::min(h.y, h.z)));
  const float min_step = ref * 0x1p-20f;
  const StepLevels levels = step_levels(h, scale, min_step, ref);
  ASSERT_GT(levels.count, 0u) << what;
  ASSERT_LE(levels.count, kMaxStepLevels) << what;
  const k::ResoctFrame f = frame_of(levels);
  const double spacing = std::ldexp(1.0, -int(23u - levels.shift));
  std::mt19937 rng(7);
  std::normal_distribution<float> n(0.0f, 1.0f);
  const glm::vec3 hf(h);
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 d(n(rng), n(rng), n(rng));
    if (i < 6) d = glm::vec3(0.0f);
    if (i < 6) d[i % 3] = i < 3 ? 1.0f : -1.0f;
    if (i >= 6 && i < 12) d[i % 3] = 1e-25f;  // parallel to a face
    if (glm::length(d) == 0.0f) continue;
    d = glm::normalize(d);
    const float dt = k::resoct_step_size(d, hf, float(scale), min_step);
    const float ratio = k::resoct_step_ratio(dt, ref);
    const std::uint32_t level = k::resoct_step_level(f, ratio);
    ASSERT_NE(level, k::RESOCT_STEP_LEVEL_NONE) << what << ": direction " << i;
    const float q = k::resoct_step_level_ratio(f, level);
    EXPECT_EQ(q, step_level_ratio(levels, level));
    ASSERT_LE(q, ratio) << what;
    ASSERT_GE(double(q) * (1.0 + spacing), double(ratio)) << what;
  }
}

TEST(StepLevels, EveryRayOfAFrameHasALevelAtMostOneSpacingBelowItsStep) {
  expect_every_direction_has_a_level({1.0 / 256, 1.0 / 256, 1.0 / 256}, 1.0, "isotropic");
  expect_every_direction_has_a_level({1.0 / 256, 1.0 / 256, 1.0 / 256}, 0.37, "step 0.37");
  expect_every_direction_has_a_level({1.0 / 128, 1.0 / 128, 1.0 / 25.6}, 1.0, "anisotropic z x5");
  expect_every_direction_has_a_level({4.0 / 256, 1.0 / 256, 1.0 / 256}, 2.5, "coarse x");
  expect_every_direction_has_a_level({1e-6, 1e-6, 3e-3}, 1.0, "anisotropic x3000");
}

TEST(StepLevels, ThirtyTwoLevelsPerOctaveUnlessTheRangeNeedsFewer) {
  const glm::dvec3 iso(1.0 / 256);
  const StepLevels a = step_levels(iso, 1.0, 1e-9f, float(iso.x));
  EXPECT_EQ(a.shift, 23u - kStepLevelBits);
  // [1, sqrt(3)] spans 24 levels of 1/32, plus one of margin on each side.
  EXPECT_EQ(a.count, 26u);
  // An axis-aligned ray of step_scale 1 is on a level exactly (the step is the reference).
  const k::ResoctFrame f = frame_of(a);
  EXPECT_EQ(k::resoct_step_level_ratio(f, k::resoct_step_level(f, 1.0f)), 1.0f);
  // A range of ~12 octaves at 32 or 16 levels each would exceed the cap: fewer per octave.
  const StepLevels wide = step_levels({1e-6, 1e-6, 3e-3}, 1.0, 1e-12f, 1e-6f);
  EXPECT_LT(wide.count, kMaxStepLevels + 1u);
  EXPECT_LT(23u - wide.shift, kStepLevelBits);
}

TEST(StepLevels, UnusableParametersGiveNoLevels) {
  const glm::dvec3 h(1.0 / 64);
  EXPECT_EQ(step_levels(h, 0.0, 0.0f, 0.01f).count, 0u);
  EXPECT_EQ(step_levels(h, std::numeric_limits<double>::infinity(), 0.0f, 0.01f).count, 0u);
  EXPECT_EQ(step_levels(h, 1.0, 0.0f, 0.0f).count, 0u);
  EXPECT_EQ(step_levels(glm::dvec3(0.0), 1.0, 0.0f, 0.01f).count, 0u);
  EXPECT_EQ(step_levels(h, std::numeric_limits<double>::quiet_NaN(), 0.0f, 0.01f).count, 0u);
  const k::ResoctFrame none = frame_of({});
  EXPECT_EQ(k::resoct_step_level(none, 1.0f), k::RESOCT_STEP_LEVEL_NONE);
  const k::ResoctFrame f = frame_of(step_levels(h, 1.0, 0.0f, float(h.x)));
  EXPECT_EQ(k::resoct_step_level(f, 0.0f), k::RESOCT_STEP_LEVEL_NONE);
  EXPECT_EQ(k::resoct_step_level(f, -1.0f), k::RESOCT_STEP_LEVEL_NONE);
  EXPECT_EQ(k::resoct_step_level(f, std::numeric_limits<float>::quiet_NaN()),
            k::RESOCT_STEP_LEVEL_NONE);
  EXPECT_EQ(k::resoct_step_level(f, 0.25f), k::RESOCT_STEP_LEVEL_NONE);  // below the range
  EXPECT_EQ(k::resoct_step_level(f, 8.0f), k::RESOCT_STEP_LEVEL_NONE);   // above it
}

TEST(StepLut, EntriesAreTheCorrectedPremultipliedTransferFunction) {
  std::vector<glm::vec4> lut{{0.2f, 0.4f, 0.6f, 0.0f},
                             {1.0f, 0.5f, 0.25f, 1e-7f},
                             {0.3f, 0.3f, 0.3f, 0.03f},
                             {0.9f, 0.1f, 0.2f, 0.4f},
                             {0.5f, 0.5f, 0.5f, 0.95f},
                             {0.7f, 0.8f, 0.9f, 1.0f},
                             {0.1f, 0.2f, 0.3f, std::numeric_limits<float>::quiet_NaN()},
                             {-1.0f, 2.0f, std::numeric_limits<float>::infinity(), 0.5f}};
  for (const float ratio : {1.0f, 1.40625f, 1.71875f, 0.5f}) {
    std::vector<glm::vec4> out(lut.size());
    step_lut(lut, ratio, out);
    for (std::size_t i = 0; i < lut.size(); ++i) {
      const double a = std::isnan(lut[i].a) ? 0.0 : 1.0 - std::pow(1.0 - double(lut[i].a), ratio);
      EXPECT_NEAR(out[i].a, a, 1e-7 * a + 1e-12) << i;
      // The kernel's per-sample correction agrees to its float precision.
      const float kernel_a = k::resoct_correct_opacity(lut[i].a, ratio);
      EXPECT_NEAR(out[i].a, kernel_a, 4e-6f * kernel_a + 1e-12f) << i;
      const glm::vec3 rgb = i == 7 ? glm::vec3(0.0f, 2.0f, 0.0f) : glm::vec3(lut[i]);
      for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(out[i][c], float(double(rgb[c]) * a)) << i;
    }
    EXPECT_EQ(out[0], glm::vec4(0.0f));
    EXPECT_EQ(out[5].a, 1.0f);
  }
  std::vector<glm::vec4> wrong(3);
  EXPECT_THROW(step_lut(lut, 1.0f, wrong), Error);
}

TEST(StepLut, KernelLookupInterpolatesTheLevelsLut) {
  // With entry i = (i, i, i, i): slot 1 of 3 levels, level 2 starts at (1 * 3 + 2) * 1024.
  const float base = float((1u * 3u + 2u) * k::RESOCT_TF_LUT_SIZE);
  const glm::vec4 mid = k::resoct_step_lut_lookup(1u, 2u, 3u, 0.5f);
  EXPECT_FLOAT_EQ(mid.a, base + 511.5f);
  EXPECT_EQ(k::resoct_step_lut_lookup(1u, 2u, 3u, -3.0f).a, base);
  EXPECT_EQ(k::resoct_step_lut_lookup(1u, 2u, 3u, 7.0f).a, base + 1023.0f);
  EXPECT_EQ(k::resoct_step_lut_lookup(1u, 2u, 3u, std::numeric_limits<float>::quiet_NaN()),
            glm::vec4(0.0f));
}

}  // namespace
}  // namespace resoct::test
