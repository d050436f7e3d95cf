// Pre-integrated transfer functions (kernel/preintegration.glsl.h as C++, table builder
// resoct::preintegration_table): against brute-force definitions in double — the table's knots
// and cumulative integrals, the point-sampled opacity-corrected lookup for equal end values, a
// fine numerical integration (10^5 sub-steps) of the emission-absorption segment without
// self-attenuation on a linear value ramp through the exact transfer function, and the hard
// cases (opaque entries, NaN, values outside [0, 1], spans far below a LUT bin).
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/scene/preintegration.hpp"
#include "resoct/scene/transfer_function.hpp"
#include "support/expect_error.hpp"

namespace resoct::kernel {
// The kernel reads LUTs and pre-integration tables through these accessors; one table per slot.
inline std::vector<std::vector<glm::vec4>> g_luts;
inline std::vector<std::vector<glm::vec4>> g_pre;
inline glm::vec4 resoct_read_tf(std::uint32_t slot, std::uint32_t index) {
  return g_luts.at(slot).at(index);
}
inline glm::vec4 resoct_read_preint(std::uint32_t slot, std::uint32_t index) {
  return g_pre.at(slot).at(index);
}
}  // namespace resoct::kernel

#include "resoct/kernel/preintegration.glsl.h"

namespace resoct {
namespace {

namespace k = kernel;

static_assert(kPreintTauMax == k::RESOCT_PREINT_TAU_MAX);
static_assert(kTfLutSize == k::RESOCT_TF_LUT_SIZE);

// Installs `tf` as slot 0 and returns it.
TransferFunction install(const TransferFunction& tf) {
  const std::vector<glm::vec4> lut = tf.lut();
  k::g_luts = {lut};
  k::g_pre = {preintegration_table(lut)};
  return tf;
}

// A smooth, everywhere-translucent TF with knots off the LUT grid.
TransferFunction smooth_tf() {
  return TransferFunction({{0.0, {0.1, 0.2, 0.9, 0.02}},
                           {0.3137, {0.9, 0.5, 0.1, 0.35}},
                           {0.7071, {0.2, 0.9, 0.4, 0.1}},
                           {1.0, {1.0, 1.0, 1.0, 0.6}}});
}

// A narrow opaque-ish peak around 0.5 on a transparent background.
TransferFunction peak_tf() {
  return TransferFunction({{0.0, {0, 0, 0, 0}},
                           {0.48, {1.0, 0.3, 0.1, 0.0}},
                           {0.5, {1.0, 0.8, 0.2, 0.9}},
                           {0.52, {0.2, 0.3, 1.0, 0.0}},
                           {1.0, {0, 0, 0, 0}}});
}

// Brute force: straight colour and opacity of a segment of `ratio` reference steps whose value
// runs linearly from a to b, extinction −ln(1 − α(v)) of the exact TF (values clamped to
// [0, 1] as lookups do), emission colour·extinction, no self-attenuation: midpoint rule with
// `steps` sub-steps.
glm::dvec4 brute_segment(const TransferFunction& tf, double a, double b, double ratio,
                         int steps = 100000) {
  double tau = 0.0;
  glm::dvec3 w(0.0);
  for (int i = 0; i < steps; ++i) {
    const double v = a + (b - a) * (i + 0.5) / steps;
    const glm::dvec4 c = tf.evaluate(std::clamp(v, 0.0, 1.0));
    const double t = c.a >= 1.0 ? double(kPreintTauMax) : -std::log1p(-c.a);
    tau += t;
    w += glm::dvec3(c) * t;
  }
  tau /= steps;
  w /= double(steps);
  if (tau <= 0.0) return glm::dvec4(0.0);
  return glm::dvec4(w / tau, -std::expm1(-ratio * tau));
}

void expect_near4(const glm::vec4& got, const glm::dvec4& want, double tol, const char* what) {
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(got[c], want[c], tol) << what << " component " << c;
  }
}

TEST(PreintTable, KnotsAndCumulativeIntegralsMatchTheirDefinition) {
  const std::vector<glm::vec4> lut = smooth_tf().lut();
  const std::vector<glm::vec4> t = preintegration_table(lut);
  ASSERT_EQ(t.size(), 2 * lut.size());
  const std::size_t n = lut.size();
  double cum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double tau = -std::log(1.0 - double(lut[i].a));
    EXPECT_NEAR(t[i].a, tau, 1e-6 * (1.0 + tau));
    EXPECT_NEAR(t[i].r, lut[i].r * tau, 1e-6);
    // Cumulative: the integral of the linear interpolant, here by Simpson's rule per bin (exact
    // for linear functions, independent of the builder's trapezoid sum).
    EXPECT_NEAR(t[n + i].a, cum, 1e-5 * (1.0 + cum)) << i;
    if (i + 1 < n) {
      const double tau1 = -std::log(1.0 - double(lut[i + 1].a));
      cum += (tau + 4.0 * 0.5 * (tau + tau1) + tau1) / 6.0;
    }
  }
}

TEST(PreintTable, OpaqueAndInvalidEntriesStayFinite) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<glm::vec4> lut = {{1, 1, 1, 1.0f},
                                      {0.5f, 0.5f, 0.5f, 1.5f},
                                      {1, 0, 0, nan},
                                      {nan, 1, 0, 0.5f},
                                      {1, 1, 1, -0.5f}};
  const std::vector<glm::vec4> t = preintegration_table(lut);
  EXPECT_EQ(t[0].a, kPreintTauMax);
  EXPECT_EQ(t[1].a, kPreintTauMax);
  EXPECT_EQ(t[2], glm::vec4(0.0f));
  EXPECT_EQ(t[3].r, 0.0f);
  EXPECT_NEAR(t[3].a, std::log(2.0), 1e-6);
  EXPECT_EQ(t[4], glm::vec4(0.0f));
  for (const glm::vec4& e : t) {
    for (int c = 0; c < 4; ++c) EXPECT_TRUE(std::isfinite(e[c]));
  }
  EXPECT_RESOCT_ERROR(preintegration_table(std::vector<glm::vec4>(1)), ErrorCode::invalid_argument,
                      "lut");
}

TEST(PreintSegment, EqualEndsAreThePointSampledCorrectedLookup) {
  install(smooth_tf());
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ratio(0.05f, 4.0f);
  // At the LUT entries the models agree up to float rounding.
  for (std::uint32_t i = 0; i < k::RESOCT_TF_LUT_SIZE; i += 37) {
    const float v = float(i) / float(k::RESOCT_TF_LUT_SIZE - 1);
    const float r = ratio(rng);
    const glm::vec4 p = k::resoct_tf_lookup(0, v);
    const glm::vec4 want(glm::vec3(p), k::resoct_correct_opacity(p.a, r));
    expect_near4(k::resoct_preint_segment(0, v, v, r), want, 2e-6, "knot");
  }
  // Between entries they differ within one bin: alpha by the convexity of −ln(1 − α) (α changes
  // by < 1e-3 per bin here), colour because it is weighted by extinction, by at most
  // |Δc| |Δτ| / (4 τ) over the bin. Both stay far below one 8-bit step.
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  for (int i = 0; i < 500; ++i) {
    const float v = value(rng);
    const float r = ratio(rng);
    const glm::vec4 p = k::resoct_tf_lookup(0, v);
    const glm::vec4 want(glm::vec3(p), k::resoct_correct_opacity(p.a, r));
    const auto b = std::min(std::uint32_t(v * 1023.0f), 1022u);
    const glm::dvec4 l0 = k::g_luts[0][b], l1 = k::g_luts[0][b + 1];
    const double t0 = -std::log1p(-l0.a), t1 = -std::log1p(-l1.a);
    const glm::dvec3 d = glm::abs(glm::dvec3(l1) - glm::dvec3(l0));
    const double dc = std::max({d.r, d.g, d.b});
    const double bound = dc * std::abs(t1 - t0) / (4.0 * std::min(t0, t1));
    expect_near4(k::resoct_preint_segment(0, v, v, r), want, 1e-5 + bound, "between knots");
  }
}

TEST(PreintSegment, MatchesFineIntegrationOnALinearRamp) {
  for (const TransferFunction& tf : {smooth_tf(), peak_tf()}) {
    install(tf);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> value(0.0, 1.0);
    std::uniform_real_distribution<double> ratio(0.25, 4.0);
    for (int i = 0; i < 40; ++i) {
      const double a = value(rng), b = value(rng), r = ratio(rng);
      const glm::dvec4 want = brute_segment(tf, a, b, r);
      const glm::vec4 got = k::resoct_preint_segment(0, float(a), float(b), float(r));
      // The LUT places the TF's knots to within half a bin (slope / 2046 in α for these TFs,
      // 0.9 / 0.02 / 2046 = 0.022 at the peak's flanks, averaged over the ramp).
      expect_near4(got, want, 2e-3, "ramp");
      // Orientation does not matter without self-attenuation.
      expect_near4(k::resoct_preint_segment(0, float(b), float(a), float(r)), glm::dvec4(got), 1e-6,
                   "reversed");
    }
  }
}

TEST(PreintSegment, CrossesAPeakThatPointSamplingMisses) {
  const TransferFunction tf = install(peak_tf());
  // Two samples on either side of the peak: the point samples see nothing.
  const glm::dvec4 want = brute_segment(tf, 0.3, 0.7, 2.0);
  EXPECT_GT(want.a, 0.05);
  expect_near4(k::resoct_preint_segment(0, 0.3f, 0.7f, 2.0f), want, 1e-3, "peak");
  EXPECT_EQ(k::resoct_tf_lookup(0, 0.3f).a, 0.0f);
  EXPECT_EQ(k::resoct_tf_lookup(0, 0.7f).a, 0.0f);
}

TEST(PreintSegment, TinySpansAcrossAKnotDoNotCancel) {
  install(peak_tf());
  const float knot = 512.0f / 1023.0f;
  const glm::vec4 mid = k::resoct_preint_segment(0, knot, knot, 1.0f);
  for (float d : {1e-9f, 1e-7f, 1e-6f, 1e-5f}) {
    const glm::vec4 s = k::resoct_preint_segment(0, knot - d, knot + d, 1.0f);
    // The integrand is continuous: the average over a short span is its value at the knot to
    // within the span times the slope (|dτ/dv| < 3000 for this TF).
    expect_near4(s, glm::dvec4(mid), 1e-5 + 3000.0 * d, "tiny span");
  }
}

TEST(PreintSegment, OpaqueEntriesGiveFullOpacity) {
  const TransferFunction tf(
      {{0.0, {0, 0, 0, 0}}, {0.4, {1, 1, 0, 0.0}}, {0.6, {1, 1, 0, 1.0}}, {1.0, {1, 0, 1, 1.0}}});
  install(tf);
  // Entirely in the opaque part: exactly opaque for any segment length.
  for (float r : {1e-3f, 0.25f, 4.0f}) {
    EXPECT_EQ(k::resoct_preint_segment(0, 0.7f, 0.9f, r).a, 1.0f);
    EXPECT_EQ(k::resoct_preint_segment(0, 0.8f, 0.8f, r).a, 1.0f);
  }
  // Half in the opaque part: the average extinction is at least 32 per reference step.
  const glm::vec4 half = k::resoct_preint_segment(0, 0.45f, 0.95f, 1.0f);
  EXPECT_EQ(half.a, 1.0f);
  EXPECT_TRUE(std::isfinite(half.r) && half.r <= 1.0f && half.r >= 0.0f);
  // The colour is the extinction-weighted average: dominated by the opaque entries.
  EXPECT_NEAR(half.g, brute_segment(tf, 0.45, 0.95, 1.0).g, 2e-3);
}

TEST(PreintSegment, NanIsTransparent) {
  install(smooth_tf());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(k::resoct_preint_segment(0, nan, 0.5f, 1.0f), glm::vec4(0.0f));
  EXPECT_EQ(k::resoct_preint_segment(0, 0.5f, nan, 1.0f), glm::vec4(0.0f));
  EXPECT_EQ(k::resoct_preint_segment(0, 0.5f, 0.5f, 0.0f), glm::vec4(0.0f));
}

// Opacity of a point of reference-step opacity from the table's knots, over `ratio` steps.
double point_alpha(float v, double ratio) {
  const glm::vec4 p = k::resoct_preint_average(0, v, v);
  return -std::expm1(-ratio * double(p.a));
}

// Runs of one channel over a march of steps of 1 reference step: a run covers exactly its
// steps (half-step points at both ends, segments between midpoints), and a NaN, a sample
// without a value and a view LOD change end the run (its tail is composited first).
TEST(PreintRun, RunsCoverExactlyTheirStepsAndEndAtNanGapsAndLevelChanges) {
  install(smooth_tf());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  k::ResoctPreintRay pr;
  k::resoct_preint_ray_clear(pr);
  glm::vec4 acc(0.0f);
  auto sample = [&](std::uint32_t lod, float v, bool has_value) {
    acc = k::resoct_preint_begin_sample(pr, lod, 1.0f, acc);
    glm::vec4 rgba(0.0f);
    if (has_value) rgba = k::resoct_preint_sample(pr, 3u, 0u, v);
    acc = k::resoct_preint_end_sample(pr, acc);
    acc = k::resoct_composite(acc, k::resoct_premultiply(glm::vec3(rgba), rgba.a));
    return rgba;
  };
  // Run 1: 0.2 (half-step point), 0.4 (segment 0.2 -> 0.4 over one step).
  EXPECT_NEAR(sample(0, 0.2f, true).a, point_alpha(0.2f, 0.5), 1e-6);
  EXPECT_NEAR(sample(0, 0.4f, true).a, k::resoct_preint_segment(0, 0.2f, 0.4f, 1.0f).a, 1e-6);
  // NaN: transparent; the run's tail (0.4 over half a step) is composited before it.
  const float before = acc.a;
  EXPECT_EQ(sample(0, nan, true), glm::vec4(0.0f));
  const double tail = point_alpha(0.4f, 0.5);
  EXPECT_NEAR(acc.a, before + (1.0 - before) * tail, 1e-6);
  // Run 2 starts from a point again, continues, then a sample without a value ends it.
  EXPECT_NEAR(sample(0, 0.9f, true).a, point_alpha(0.9f, 0.5), 1e-6);
  EXPECT_NEAR(sample(0, 0.1f, true).a, k::resoct_preint_segment(0, 0.9f, 0.1f, 1.0f).a, 1e-6);
  float a0 = acc.a;
  sample(0, 0.0f, false);
  EXPECT_NEAR(acc.a, a0 + (1.0 - a0) * point_alpha(0.1f, 0.5), 1e-6);
  // Run 3 at level 0, then a level change: tail of 0.6, and 0.7 starts a new run as a point.
  sample(0, 0.6f, true);
  a0 = acc.a;
  const glm::vec4 after_change = sample(1, 0.7f, true);
  EXPECT_NEAR(after_change.a, point_alpha(0.7f, 0.5), 1e-6);
  const double with_tail = a0 + (1.0 - a0) * point_alpha(0.6f, 0.5);
  EXPECT_NEAR(acc.a, with_tail + (1.0 - with_tail) * after_change.a, 1e-6);
  // The end of the ray flushes the open run: 0.7 over half a step.
  a0 = acc.a;
  acc = k::resoct_preint_flush(pr, acc);
  EXPECT_NEAR(acc.a, a0 + (1.0 - a0) * point_alpha(0.7f, 0.5), 1e-6);
  EXPECT_EQ(k::resoct_preint_flush(pr, acc), acc);
}

// A constant value over a whole run gives the same total opacity as point sampling the same
// steps with opacity correction: the run integrates exactly the steps it sampled.
TEST(PreintRun, ConstantRunEqualsPointSamplingOfTheSameSteps) {
  install(smooth_tf());
  const float v = 0.6f;
  k::ResoctPreintRay pr;
  k::resoct_preint_ray_clear(pr);
  glm::vec4 pre(0.0f), point(0.0f);
  const float steps[] = {1.0f, 1.0f, 0.5f, 1.0f, 0.3f};
  for (float st : steps) {
    pre = k::resoct_preint_begin_sample(pr, 0u, st, pre);
    const glm::vec4 s = k::resoct_preint_sample(pr, 0u, 0u, v);
    pre = k::resoct_preint_end_sample(pr, pre);
    pre = k::resoct_composite(pre, k::resoct_premultiply(glm::vec3(s), s.a));
    const glm::vec4 p = k::resoct_preint_segment(0, v, v, st);
    point = k::resoct_composite(point, k::resoct_premultiply(glm::vec3(p), p.a));
  }
  pre = k::resoct_preint_flush(pr, pre);
  // Opacity exactly (up to float rounding); colour up to the tail colour's 8-bit storage
  // (half a step of 1/255 times the tail's opacity).
  EXPECT_NEAR(pre.a, point.a, 2e-6);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(pre[c], point[c], 0.5 / 255.0) << c;
}

TEST(PreintSegment, ValuesOutsideTheRangeTakeTheEndEntries) {
  const TransferFunction tf = install(smooth_tf());
  const float inf = std::numeric_limits<float>::infinity();
  // Wholly outside: the end entries' point values.
  expect_near4(k::resoct_preint_segment(0, -3.0f, -0.5f, 1.0f),
               glm::dvec4(k::resoct_preint_segment(0, 0.0f, 0.0f, 1.0f)), 1e-6, "below");
  expect_near4(k::resoct_preint_segment(0, 1.5f, inf, 1.0f),
               glm::dvec4(k::resoct_preint_segment(0, 1.0f, 1.0f, 1.0f)), 1e-6, "above");
  expect_near4(k::resoct_preint_segment(0, -inf, -inf, 1.0f),
               glm::dvec4(k::resoct_preint_segment(0, 0.0f, 0.0f, 1.0f)), 1e-6, "-inf");
  // Straddling an end: the clamped TF averaged over the whole span.
  expect_near4(k::resoct_preint_segment(0, -0.5f, 0.5f, 1.5f), brute_segment(tf, -0.5, 0.5, 1.5),
               2e-3, "straddle 0");
  expect_near4(k::resoct_preint_segment(0, 0.8f, 1.7f, 0.5f), brute_segment(tf, 0.8, 1.7, 0.5),
               2e-3, "straddle 1");
  expect_near4(k::resoct_preint_segment(0, -0.2f, 1.2f, 3.0f), brute_segment(tf, -0.2, 1.2, 3.0),
               2e-3, "both ends");
}

}  // namespace
}  // namespace resoct
