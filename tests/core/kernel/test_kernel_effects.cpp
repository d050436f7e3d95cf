// The effect kernels (isosurface refinement, cubic roots, gradients) called directly in C++ over
// accessors defined here, on bricks produced by the real ResidentScene path, against brute-force
// double-precision definitions: the first crossing of the trilinear field (dense scan +
// bisection), central differences of the clamp-to-edge trilinear field, analytic normals.
#include <cmath>
#include <cstring>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "resoct/scene/camera.hpp"
#include "resoct/kernel/frame.glsl.h"
#include "support/function_source.hpp"
#include "support/recording_backend.hpp"
#include "support/resident_scene.hpp"

namespace resoct::test {
namespace {
// What the accessors read (one test at a time; tests are single-threaded).
struct Ctx {
  const RecordingBackend* backend = nullptr;
  const std::vector<std::uint32_t>* offsets = nullptr;
  const FrameTables* tables = nullptr;
  glm::ivec3 padded{1};
};
Ctx g;
}  // namespace
}  // namespace resoct::test

namespace resoct::kernel {
inline uint resoct_read_node(uint i) {
  return test::g.backend->nodes()[i];
}
inline uint resoct_read_page(uint i) {
  return test::g.backend->pages()[i];
}
inline uint resoct_read_directory(uint i) {
  return test::g.backend->directory()[i];
}
inline uint resoct_read_directory_offset(uint t) {
  return (*test::g.offsets)[t];
}
inline ResoctSlotInfo resoct_read_slot(uint i) {
  return test::g.tables->slots[i];
}
inline ResoctLevelInfo resoct_read_level(uint l) {
  return test::g.tables->levels[l];
}
inline ResoctDepthInfo resoct_read_depth(uint d) {
  return test::g.tables->depths[d];
}
inline vec4 resoct_read_tf(uint slot, uint index) {
  return test::g.tables->tf_luts[std::size_t(slot) * 1024u + index];
}
inline vec4 resoct_read_preint(uint slot, uint index) {
  return test::g.tables->preint_tables[std::size_t(slot) * 2048u + index];
}
inline vec4 resoct_read_step_lut(uint index) {
  return test::g.tables->step_luts[index];
}
inline uint resoct_read_visible_subtrees(uint node) {
  const auto& bits = test::g.tables->visible_subtrees;
  return bits.empty() ? 0u : bits[node];
}
inline ResoctFxFrame resoct_read_fx_frame() {
  return test::g.tables->fx;
}
inline float resoct_read_level_size_log2(uint l) {
  return test::g.tables->levels[l].size_log2;
}
// f32 trilinear in padded-brick coordinates, clamp-to-edge (as both backends).
inline float resoct_sample_cache(uint slot, vec3 pos) {
  const auto bytes = test::g.backend->slot_voxels(slot);
  const glm::ivec3 p = test::g.padded;
  auto at = [&](int x, int y, int z) {
    float v;
    std::memcpy(&v, bytes.data() + 4 * (std::size_t(z * p.y + y) * std::size_t(p.x) + x), 4);
    return v;
  };
  float c[3];
  int i0[3];
  for (int a = 0; a < 3; ++a) {
    c[a] = std::clamp(pos[a] - 0.5f, 0.0f, float(p[a] - 1));
    i0[a] = std::min(int(c[a]), std::max(p[a] - 2, 0));
    c[a] -= float(i0[a]);
  }
  float r = 0.0f;
  for (int k = 0; k < 8; ++k) {
    float w = 1.0f;
    int q[3];
    for (int a = 0; a < 3; ++a) {
      const bool up = (k >> a) & 1;
      q[a] = std::min(i0[a] + (up ? 1 : 0), p[a] - 1);
      w *= up ? c[a] : 1.0f - c[a];
    }
    r += w * at(q[0], q[1], q[2]);
  }
  return r;
}
inline void resoct_report_request(uint) {}
inline void resoct_report_node_request(uint) {}
inline void resoct_mark_used(uint) {}
}  // namespace resoct::kernel

#include "resoct/kernel/traverse.glsl.h"

namespace resoct::test {
namespace {

namespace k = resoct::kernel;

// Everything resident for a one-channel f32 FunctionSource, with the accessors pointed at it.
struct KernelRig {
  FunctionSource src;
  ResidentScene rs;
  RecordingBackend backend;
  FrameTables tables;

  KernelRig(VolumeDesc v, BrickLayout layout, FunctionSource::ValueFn fn, const Scene& scene)
      : src(v, layout, std::move(fn)), rs(src, {0}) {
    rs.upload(backend);
    tables = rs.tables(scene);
    g.backend = &backend;
    g.offsets = &rs.pages().directory_offsets();
    g.tables = &tables;
    g.padded = glm::ivec3(layout.padded_size());
  }
  k::ResoctSampleParams sp() const { return k::resoct_sample_params(tables.frame); }
  k::ResoctFxParams fxp() const { return k::resoct_fx_params(tables.frame, tables.fx); }
};

VolumeDesc f32_volume(glm::u64vec3 extent, double lo, double hi, glm::dvec3 spacing = {1, 1, 1}) {
  VolumeDesc v;
  v.extent = extent;
  v.spacing = spacing;
  v.type = VoxelType::f32;
  v.ranges = {ValueRange{lo, hi}};
  return v;
}

Scene iso_scene(double iso) {
  Scene s;
  s.camera.eye = {2, 2, 2};
  s.viewport = {8, 8};
  ChannelSettings c;
  c.tf = TransferFunction({{0.0, {1, 1, 1, 1}}, {1.0, {1, 1, 1, 1}}});
  c.mode = ChannelMode::iso;
  c.isovalues = {iso};
  c.finest_level = 0;
  c.coarsest_level = 0;
  s.channels = {c};
  return s;
}

// The exact trilinear field of level 0 (clamp-to-edge), in double, at a level-0 position.
double trilinear(const FunctionSource& src, glm::dvec3 p) {
  const glm::u64vec3 e = src.hierarchy().volume().extent;
  double r = 0.0;
  glm::i64vec3 i0;
  glm::dvec3 f;
  for (int a = 0; a < 3; ++a) {
    const double x = std::clamp(p[a] - 0.5, 0.0, double(e[a]) - 1.0);
    i0[a] = std::int64_t(std::min(std::floor(x), std::max(double(e[a]) - 2.0, 0.0)));
    f[a] = x - double(i0[a]);
  }
  for (int c = 0; c < 8; ++c) {
    glm::i64vec3 q;
    double w = 1.0;
    for (int a = 0; a < 3; ++a) {
      const bool up = (c >> a) & 1;
      q[a] = std::min<std::int64_t>(i0[a] + (up ? 1 : 0), std::int64_t(e[a]) - 1);
      w *= up ? f[a] : 1.0 - f[a];
    }
    if (w != 0.0) r += w * src.voxel(0, 0, q);
  }
  return r;
}

// First crossing of `raw_iso` along origin + t dir (level-0 voxel units) in [t0, t1]: dense scan
// with 1/256-voxel steps, then 200 bisections.
std::optional<double> reference_hit(const FunctionSource& src, glm::dvec3 o, glm::dvec3 d,
                                    double t0, double t1, double raw_iso) {
  const double h = 1.0 / 256.0;
  double a = t0;
  double fa = trilinear(src, o + a * d) - raw_iso;
  for (double b = t0 + h; a < t1; b += h) {
    b = std::min(b, t1);
    const double fb = trilinear(src, o + b * d) - raw_iso;
    if (fa == 0.0) return a;
    if ((fa < 0.0) != (fb < 0.0)) {
      for (int i = 0; i < 200; ++i) {
        const double m = 0.5 * (a + b);
        const double fm = trilinear(src, o + m * d) - raw_iso;
        if ((fm < 0.0) == (fa < 0.0)) {
          a = m;
          fa = fm;
        } else {
          b = m;
        }
      }
      return 0.5 * (a + b);
    }
    a = b;
    fa = fb;
  }
  return std::nullopt;
}

void split(glm::dvec3 p, glm::ivec3& cell, glm::vec3& frac) {
  const glm::dvec3 c = glm::floor(p);
  cell = glm::ivec3(c);
  frac = glm::vec3(p - c);
}

TEST(KernelEffects, CubicRootsIncludingDoubleAndTripleRoots) {
  auto poly = [](double r0, double r1, double r2, double scale) {
    // scale (s − r0)(s − r1)(s − r2)
    const double c2 = -(r0 + r1 + r2), c1 = r0 * r1 + r0 * r2 + r1 * r2, c0 = -r0 * r1 * r2;
    return glm::vec4(float(scale * c0), float(scale * c1), float(scale * c2), float(scale));
  };
  EXPECT_NEAR(k::resoct_cubic_first_root(poly(0.5, 1.7, 2.9, 1.0), 3.0f), 0.5, 1e-6);
  EXPECT_NEAR(k::resoct_cubic_first_root(poly(-1.0, 2.25, 5.0, -3.0), 3.0f), 2.25, 1e-6);
  // Double root (ray tangent to the surface) at an extremum that evaluates to exactly 0.
  EXPECT_NEAR(k::resoct_cubic_first_root(poly(1.5, 1.5, 4.0, 1.0), 3.0f), 1.5, 1e-6);
  // Double root followed by a simple one inside the interval: the first is reported.
  EXPECT_NEAR(k::resoct_cubic_first_root(poly(1.0, 1.0, 2.0, 2.0), 3.0f), 1.0, 1e-6);
  // Triple root.
  EXPECT_NEAR(k::resoct_cubic_first_root(poly(0.75, 0.75, 0.75, 1.0), 3.0f), 0.75, 2e-3);
  // Near-tangent miss (extremum slightly above zero) and no roots: -1, never NaN.
  glm::vec4 miss = poly(1.5, 1.5, 4.0, 1.0);
  miss.x -= 1e-3f;  // the double root at 1.5 is a maximum: now just below zero
  EXPECT_EQ(k::resoct_cubic_first_root(miss, 3.0f), -1.0f);
  EXPECT_EQ(k::resoct_cubic_first_root(glm::vec4(1.0f, 0.0f, 0.0f, 0.0f), 3.0f), -1.0f);
  // Degenerate: linear and quadratic.
  EXPECT_NEAR(k::resoct_cubic_first_root(glm::vec4(-1.0f, 2.0f, 0.0f, 0.0f), 3.0f), 0.5, 1e-6);
  EXPECT_NEAR(k::resoct_cubic_first_root(glm::vec4(-4.0f, 0.0f, 1.0f, 0.0f), 3.0f), 2.0, 1e-6);
  // Random cubics against a dense double scan.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 500; ++i) {
    const glm::vec4 c(float(u(rng)), float(u(rng)), float(u(rng)), float(u(rng)));
    auto f = [&](double s) { return c.x + s * (c.y + s * (c.z + s * double(c.w))); };
    double expect = -1.0;
    for (int j = 0; j < 30000 && expect < 0.0; ++j) {
      const double a = 3.0 * j / 30000.0, b = 3.0 * (j + 1) / 30000.0;
      if (f(a) == 0.0 || (f(a) < 0.0) != (f(b) < 0.0)) expect = a;
    }
    const float got = k::resoct_cubic_first_root(c, 3.0f);
    if (expect < 0.0) {
      EXPECT_EQ(got, -1.0f) << i;
    } else {
      EXPECT_NEAR(got, expect, 2e-4) << i;
    }
  }
}

// Sphere of radius 11 voxels centred off-grid in 40^3 (bricks of 8: the surface crosses many
// brick borders), value = distance from the centre. Hits of rays in all directions within 1e-3
// voxel of the exact trilinear crossing; normals within 0.5° of the double-precision central
// difference and within 0.5° of the analytic radial normal.
TEST(KernelEffects, SphereIsosurfaceHitsAndNormals) {
  const glm::dvec3 centre(20.3, 19.6, 20.1);
  const double radius = 11.0;
  auto fn = [centre](std::uint32_t, const glm::u64vec3& v) {
    return glm::length(glm::dvec3(v) + 0.5 - centre);
  };
  const double iso = radius / 40.0;
  for (std::uint32_t halo : {1u, 2u}) {
    KernelRig rig(f32_volume({40, 40, 40}, 0.0, 40.0), BrickLayout{glm::uvec3(8), halo}, fn,
                  iso_scene(iso));
    const k::ResoctSlotInfo slot = rig.tables.slots[0];
    std::mt19937 rng(5);
    std::normal_distribution<double> n(0.0, 1.0);
    double worst_hit = 0.0, worst_ref_angle = 0.0, worst_true_angle = 0.0;
    int hits = 0;
    for (int r = 0; r < 300; ++r) {
      // From outside toward a random point inside the sphere.
      glm::dvec3 dir = glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
      const glm::dvec3 aim = centre + 6.0 * glm::dvec3(n(rng), n(rng), n(rng)) / 3.0;
      const glm::dvec3 origin = aim - 19.0 * dir;
      glm::ivec3 oc;
      glm::vec3 of;
      split(origin, oc, of);
      const double t1 = 19.0;
      const auto ref = reference_hit(rig.src, origin, dir, 0.0, t1, radius);
      float th = 0.0f;
      const bool ok = k::resoct_iso_refine(rig.sp(), rig.fxp(), slot, 0u, float(iso), oc, of,
                                           glm::vec3(dir), 0.0f, float(t1), th);
      ASSERT_EQ(ok, ref.has_value()) << r;
      if (!ok) continue;
      ++hits;
      worst_hit = std::max(worst_hit, std::abs(double(th) - *ref));
      // Normal at the hit: the kernel's central differences vs the double definition.
      const glm::dvec3 p = origin + *ref * dir;
      glm::ivec3 hc;
      glm::vec3 hf;
      split(p, hc, hf);
      const glm::vec3 gk = k::resoct_gradient(rig.sp(), rig.fxp(), slot, 0u, hc, hf, float(iso));
      glm::dvec3 gr;
      for (int a = 0; a < 3; ++a) {
        glm::dvec3 e(0.0);
        e[a] = 1.0;
        gr[a] = (trilinear(rig.src, p + e) - trilinear(rig.src, p - e)) / 2.0;
      }
      auto angle = [](glm::dvec3 a, glm::dvec3 b) {
        return glm::degrees(
            std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
      };
      worst_ref_angle = std::max(worst_ref_angle, angle(glm::dvec3(gk), gr));
      worst_true_angle = std::max(worst_true_angle, angle(glm::dvec3(gk), p - centre));
    }
    EXPECT_GT(hits, 250);
    // About three times the measured errors (2.6e-6 voxel, < 5e-4 deg, 0.105 deg): a hit off by
    // a hundredth of a voxel or a normal off by a third of a degree fails.
    EXPECT_LE(worst_hit, 1e-5) << "halo " << halo;
    EXPECT_LE(worst_ref_angle, 0.01) << "halo " << halo;
    EXPECT_LE(worst_true_angle, 0.3) << "halo " << halo;
    std::printf(
        "halo %u: %d hits, max hit error %.2e voxel, normal vs reference %.3f deg, vs "
        "analytic %.3f deg\n",
        halo, hits, worst_hit, worst_ref_angle, worst_true_angle);
  }
}

// Voxel values are integers along x (v = x), the isovalue equals voxel 9's value exactly: a ray
// along x hits at that voxel's centre, x = 9.5, and a ray starting exactly there hits at t = 0.
TEST(KernelEffects, IsovalueEqualToVoxelValues) {
  auto fn = [](std::uint32_t, const glm::u64vec3& v) { return double(v.x); };
  const double iso = 9.0 / 31.0;
  KernelRig rig(f32_volume({32, 16, 16}, 0.0, 31.0), BrickLayout{glm::uvec3(8), 1}, fn,
                iso_scene(iso));
  const k::ResoctSlotInfo slot = rig.tables.slots[0];
  // The isovalue exactly as the kernel normalizes voxel value 9.
  const float exact = (9.0f - slot.range_lo) * slot.inv_range_width;
  float th = -1.0f;
  ASSERT_TRUE(k::resoct_iso_refine(rig.sp(), rig.fxp(), slot, 0u, exact, glm::ivec3(2, 7, 7),
                                   glm::vec3(0.25f, 0.5f, 0.5f), glm::vec3(1, 0, 0), 0.0f, 20.0f,
                                   th));
  EXPECT_NEAR(th, 7.25, 1e-4);
  ASSERT_TRUE(k::resoct_iso_refine(rig.sp(), rig.fxp(), slot, 0u, exact, glm::ivec3(9, 7, 7),
                                   glm::vec3(0.5f, 0.5f, 0.5f), glm::vec3(1, 0, 0), 0.0f, 5.0f,
                                   th));
  EXPECT_NEAR(th, 0.0, 1e-5);
  // An isovalue the field never reaches is never hit.
  EXPECT_FALSE(k::resoct_iso_refine(rig.sp(), rig.fxp(), slot, 0u, float(40.0 / 31.0),
                                    glm::ivec3(2, 7, 7), glm::vec3(0.5f), glm::vec3(1, 0, 0), 0.0f,
                                    20.0f, th));
}

// A linear ramp v = 3x + 5y − 2z (level-0 voxel units) with spacing 1:2:4: the box-space
// gradient is exact everywhere inside (every tap pair straddles the position symmetrically),
// across brick borders, with the halo fast path (2) and with neighbour lookups (1), central and
// forward.
TEST(KernelEffects, RampGradientIsAnalyticWithAnisotropicSpacing) {
  auto fn = [](std::uint32_t, const glm::u64vec3& v) {
    return 3.0 * double(v.x) + 5.0 * double(v.y) - 2.0 * double(v.z) + 100.0;
  };
  const double lo = 0.0, hi = 400.0;
  const VolumeDesc vol = f32_volume({24, 20, 12}, lo, hi, {1.0, 2.0, 4.0});
  const glm::dvec3 vpb = 1.0 / box_voxel_size(vol);
  // d(normalized)/d(box) = d(raw)/d(voxel) * voxels per box / range width.
  const glm::dvec3 expect = glm::dvec3(3.0, 5.0, -2.0) * vpb / (hi - lo);
  for (std::uint32_t halo : {1u, 2u}) {
    for (GradientStencil st : {GradientStencil::central, GradientStencil::forward}) {
      Scene s = iso_scene(0.5);
      s.gradient = st;
      KernelRig rig(vol, BrickLayout{glm::uvec3(8), halo}, fn, s);
      const k::ResoctSlotInfo slot = rig.tables.slots[0];
      std::mt19937 rng(3);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (int i = 0; i < 200; ++i) {
        // Interior positions (one voxel + half a voxel from the faces), many next to borders.
        const glm::dvec3 p(1.5 + u(rng) * 20.0, 1.5 + u(rng) * 16.0, 1.5 + u(rng) * 8.0);
        glm::ivec3 c;
        glm::vec3 f;
        split(p, c, f);
        const glm::vec3 gk = k::resoct_gradient(rig.sp(), rig.fxp(), slot, 0u, c, f, 0.0f);
        for (int a = 0; a < 3; ++a) {
          EXPECT_NEAR(gk[a], expect[a], 1e-4 * std::abs(expect[a]) + 1e-5)
              << "halo " << halo << " axis " << a;
        }
      }
    }
  }
}

}  // namespace
}  // namespace resoct::test
