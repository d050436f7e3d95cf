// kernel/composite.glsl.h compiled as C++: opacity correction identities and stability,
// front-to-back compositing against closed forms, and the intermixing formula.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace resoct::kernel {
// step.glsl.h needs the level table accessor; the march below does not select levels.
inline float resoct_read_level_size_log2(std::uint32_t level) {
  return float(level);
}
}  // namespace resoct::kernel

#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/step.glsl.h"

namespace {

using namespace resoct::kernel;

// Definition in double: 1 − (1 − α)^r.
double corrected(double alpha, double r) {
  return -std::expm1(r * std::log1p(-alpha));
}

TEST(KernelComposite, OpacityCorrectionMatchesDefinition) {
  for (float alpha :
       {1e-9f, 1e-6f, 1e-3f, 0.05f, 0.0625f, 0.07f, 0.3f, 0.5f, 0.9f, 0.999f, 0.999999f}) {
    for (float r : {1e-6f, 1e-3f, 0.0625f, 0.25f, 1.0f, 2.0f, 4.0f, 8.0f}) {
      const double expect = corrected(alpha, r);
      const float got = resoct_correct_opacity(alpha, r);
      EXPECT_NEAR(got, expect, 3e-6 * expect + 1e-12) << "alpha " << alpha << " r " << r;
    }
  }
}

TEST(KernelComposite, OpacityCorrectionIdentities) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const float alpha = u(rng);
    // Δ = Δ₀ gives α back.
    EXPECT_NEAR(resoct_correct_opacity(alpha, 1.0f), alpha, 2e-6f * alpha + 1e-7f);
    // Two half steps compose to one full step: 1 − (1 − α')² = α.
    const float half = resoct_correct_opacity(alpha, 0.5f);
    EXPECT_NEAR(1.0f - (1.0f - half) * (1.0f - half), alpha, 2e-6f);
  }
  EXPECT_EQ(resoct_correct_opacity(1.0f, 1e-6f), 1.0f);
  EXPECT_EQ(resoct_correct_opacity(1.0f, 8.0f), 1.0f);
  EXPECT_EQ(resoct_correct_opacity(0.0f, 8.0f), 0.0f);
  EXPECT_EQ(resoct_correct_opacity(0.5f, 0.0f), 0.0f);
  EXPECT_EQ(resoct_correct_opacity(std::nanf(""), 1.0f), 0.0f);
  EXPECT_EQ(resoct_correct_opacity(-0.5f, 1.0f), 0.0f);
}

TEST(KernelComposite, TinyStepsAreStable) {
  // 1e-3 voxel steps at low opacity: relative error stays small where the naive float formula
  // 1 − pow(1 − α, r) loses all digits.
  const float alpha = 1e-4f;
  const float r = 1e-3f;
  const double expect = corrected(alpha, r);
  const float got = resoct_correct_opacity(alpha, r);
  EXPECT_NEAR(got / expect, 1.0, 1e-5);
  const float naive = 1.0f - std::pow(1.0f - alpha, r);
  EXPECT_GT(std::abs(naive / expect - 1.0), 1e-3);  // the reason for the series
}

TEST(KernelComposite, FrontToBackOverIdenticalSamplesIsClosedForm) {
  // N samples of colour c and reference alpha α at step ratio r: opacity 1 − (1 − α)^(N r),
  // colour c times that opacity.
  const vec3 c(0.2f, 0.6f, 1.0f);
  for (float r : {0.0625f, 0.5f, 1.0f, 3.0f}) {
    for (int n : {1, 10, 100}) {
      const float alpha = 0.05f;
      const float a = resoct_correct_opacity(alpha, r);
      vec4 acc(0.0f);
      for (int i = 0; i < n; ++i) acc = resoct_composite(acc, resoct_premultiply(c, a));
      const double total = 1.0 - std::pow(1.0 - double(alpha), double(n) * r);
      EXPECT_NEAR(acc.a, total, 2e-5);
      EXPECT_NEAR(acc.r, 0.2 * total, 2e-5);
      EXPECT_NEAR(acc.b, 1.0 * total, 2e-5);
    }
  }
}

TEST(KernelComposite, EarlyTerminationAndBackground) {
  vec4 acc(0.0f);
  int steps = 0;
  while (!resoct_saturated(acc, 0.99f) && steps < 1000) {
    acc = resoct_composite(acc, resoct_premultiply(vec3(1.0f), 0.5f));
    ++steps;
  }
  // 1 − 0.5^n >= 0.99 first at n = 7.
  EXPECT_EQ(steps, 7);
  // Over an opaque background the result is opaque and the background fills the rest.
  const vec4 out =
      resoct_over_background(vec4(0.25f, 0.0f, 0.0f, 0.5f), vec4(0.0f, 1.0f, 0.0f, 1.0f));
  EXPECT_FLOAT_EQ(out.a, 1.0f);
  EXPECT_FLOAT_EQ(out.r, 0.25f);
  EXPECT_FLOAT_EQ(out.g, 0.5f);
  const vec4 straight = resoct_unpremultiply(vec4(0.25f, 0.0f, 0.0f, 0.5f));
  EXPECT_FLOAT_EQ(straight.r, 0.5f);
  EXPECT_EQ(resoct_unpremultiply(vec4(0.0f)), vec4(0.0f));
}

vec4 mix_all(const std::vector<vec4>& samples) {
  vec4 weighted;
  float combined;
  resoct_mix_begin(weighted, combined);
  for (const vec4& s : samples) resoct_mix_add(weighted, combined, vec3(s), s.a);
  return resoct_mix_result(weighted, combined);
}

TEST(KernelComposite, IntermixingSingleChannelIsPlainCompositing) {
  const vec4 s(0.3f, 0.7f, 0.1f, 0.4f);
  const vec4 m = mix_all({s});
  EXPECT_FLOAT_EQ(m.a, 0.4f);
  EXPECT_FLOAT_EQ(m.r, 0.3f * 0.4f);
  EXPECT_FLOAT_EQ(m.g, 0.7f * 0.4f);
  EXPECT_EQ(mix_all({vec4(1.0f, 1.0f, 1.0f, 0.0f)}), vec4(0.0f));
}

TEST(KernelComposite, IntermixingMatchesFormulaAndIsOrderIndependent) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<vec4> s(std::size_t(1 + trial % 6));
    for (vec4& x : s) x = vec4(u(rng), u(rng), u(rng), u(rng) * u(rng));
    // Definition: α = 1 − Π(1 − α_c), rgb = α Σ α_c c_c / Σ α_c.
    double transmit = 1.0, wsum = 0.0;
    glm::dvec3 wrgb(0.0);
    for (const vec4& x : s) {
      transmit *= 1.0 - x.a;
      wsum += x.a;
      wrgb += double(x.a) * glm::dvec3(vec3(x));
    }
    const double alpha = 1.0 - transmit;
    const vec4 m = mix_all(s);
    EXPECT_NEAR(m.a, alpha, 1e-6);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], alpha * wrgb[c] / wsum, 1e-6);
    std::vector<vec4> reversed(s.rbegin(), s.rend());
    std::shuffle(reversed.begin(), reversed.end(), rng);
    const vec4 m2 = mix_all(reversed);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(m[c], m2[c], 1e-6);
  }
}

TEST(KernelComposite, CorrectionCommutesWithIntermixing) {
  // Correcting each channel then mixing equals mixing the reference alphas then correcting.
  const float a1 = 0.3f, a2 = 0.6f, r = 0.37f;
  const vec4 mixed_then = mix_all({vec4(1.0f, 0.0f, 0.0f, a1), vec4(0.0f, 1.0f, 0.0f, a2)});
  const vec4 corrected_first = mix_all({vec4(1.0f, 0.0f, 0.0f, resoct_correct_opacity(a1, r)),
                                        vec4(0.0f, 1.0f, 0.0f, resoct_correct_opacity(a2, r))});
  EXPECT_NEAR(corrected_first.a, resoct_correct_opacity(mixed_then.a, r), 1e-6f);
}

TEST(KernelComposite, FloatMarchThroughConstantMediumMatchesClosedForm) {
  // The kernel pieces together (slab test, Eq. 8.2-8.3 step, segments cut at the exit, opacity
  // correction, front-to-back) reproduce 1 − exp(−σL) in float for steps 1/16 .. 4 voxels and
  // oblique rays, where L is the true chord length. Box (1, 0.5, 0.25), 64 x 32 x 16 voxels.
  const vec3 box(1.0f, 0.5f, 0.25f);
  const vec3 h(1.0f / 64.0f);
  const float delta0 = 1.0f / 64.0f;
  const float alpha = 0.03f;
  const double sigma = -std::log(1.0 - double(alpha)) / double(delta0);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (float scale : {1.0f / 16.0f, 0.125f, 0.25f, 0.5f, 1.0f, 2.0f, 4.0f}) {
    for (int i = 0; i < 20; ++i) {
      vec3 dir = glm::normalize(vec3(u(rng), u(rng), u(rng)));
      if (i == 0) dir = vec3(1.0f, 0.0f, 0.0f);
      const vec3 origin = vec3(0.5f, 0.25f, 0.125f) - 2.0f * dir;
      const vec2 span = resoct_ray_box(origin, dir, vec3(0.0f), box);
      ASSERT_TRUE(resoct_ray_hits(span, 0.0f));
      const float dt = resoct_step_size(dir, h, scale, 1e-6f);
      vec4 acc(0.0f);
      int iterations = 0;
      for (float t = span.x; t < span.y && iterations < 100000; ++iterations) {
        const float len = resoct_segment_length(t, dt, span.y);
        acc = resoct_composite(
            acc, resoct_premultiply(vec3(1.0f), resoct_correct_opacity(alpha, len / delta0)));
        t = resoct_advance_t(t, len);
      }
      ASSERT_LT(iterations, 100000);
      const double length = double(span.y) - double(span.x);
      const double expect = 1.0 - std::exp(-sigma * length);
      EXPECT_NEAR(acc.a, expect, 2e-5) << "scale " << scale << " ray " << i;
    }
  }
}

}  // namespace
