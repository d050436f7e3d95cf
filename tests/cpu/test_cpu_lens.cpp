// The lens through the CPU backend against brute-force definitions: requests only for bricks that
// intersect the (oriented) lens box, exact clipping of a constant medium (closed form along the
// ray's path through the box), the outside level range (bit-identical to a plain scene at that
// range where rays miss the lens), and a 65536^3 volume that pages in only the lens'
// neighbourhood.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "support/expect_error.hpp"
#include "resoct/scene/camera.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"

namespace resoct::test {
namespace {

BrickLayout bricks(std::uint32_t size) {
  BrickLayout l;
  l.brick_size = glm::uvec3(size);
  l.halo = 1;
  return l;
}

Camera perspective() {
  Camera c;
  c.eye = {1.7, 1.2, 1.9};
  c.target = {0.5, 0.5, 0.5};
  c.fov_deg = 40.0;
  return c;
}

Camera ortho_down_z(double height) {
  Camera c;
  c.eye = {0.5, 0.5, 2.0};
  c.target = {0.5, 0.5, 0.5};
  c.projection = Projection::orthographic;
  c.ortho_height = height;
  return c;
}

glm::dmat3 rotation(double yaw_deg, double pitch_deg) {
  const double a = glm::radians(yaw_deg), b = glm::radians(pitch_deg);
  const glm::dmat3 rz(glm::dvec3(std::cos(a), std::sin(a), 0),
                      glm::dvec3(-std::sin(a), std::cos(a), 0), glm::dvec3(0, 0, 1));
  const glm::dmat3 rx(glm::dvec3(1, 0, 0), glm::dvec3(0, std::cos(b), std::sin(b)),
                      glm::dvec3(0, -std::sin(b), std::cos(b)));
  return rz * rx;
}

// Separating-axis test of an axis-aligned box [lo, hi] against the lens (both in box units):
// exact for two boxes with the 15 candidate axes.
bool box_meets_lens(const glm::dvec3& lo, const glm::dvec3& hi, const Lens& lens) {
  const glm::dvec3 c = 0.5 * (lo + hi), e = 0.5 * (hi - lo), h = 0.5 * lens.size;
  const glm::dvec3 d = lens.center - c;
  std::vector<glm::dvec3> axes = {{1, 0, 0},    {0, 1, 0},    {0, 0, 1},
                                  lens.axes[0], lens.axes[1], lens.axes[2]};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      glm::dvec3 u(0.0);
      u[i] = 1.0;
      const glm::dvec3 x = glm::cross(u, lens.axes[j]);
      if (glm::length(x) > 1e-9) axes.push_back(glm::normalize(x));
    }
  }
  for (const glm::dvec3& a : axes) {
    const double ra = e.x * std::abs(a.x) + e.y * std::abs(a.y) + e.z * std::abs(a.z);
    double rb = 0.0;
    for (int k = 0; k < 3; ++k) rb += h[k] * std::abs(glm::dot(lens.axes[k], a));
    if (std::abs(glm::dot(d, a)) > ra + rb + 1e-9) return false;
  }
  return true;
}

// Box-unit box of a brick of `level` (level-0 voxels of a cubic volume of `extent` voxels).
std::pair<glm::dvec3, glm::dvec3> brick_box(const BrickHierarchy& h, std::uint32_t level,
                                            glm::uvec3 brick, double extent) {
  const glm::dvec3 size0 = glm::dvec3(h.layout().brick_size) * glm::dvec3(1u << level);
  const glm::dvec3 lo = glm::dvec3(brick) * size0;
  return {lo / extent, glm::min(lo + size0, glm::dvec3(extent)) / extent};
}

const std::vector<TfPoint> kVisible = {{0.0, {1, 0.5, 0.2, 0.02}}, {1.0, {0.2, 0.5, 1, 0.05}}};

TEST(CpuLens, RequestsOnlyBricksMeetingTheLens) {
  ProceduralSource src("procedural:ramp:128x128x128", bricks(8));
  ResidentOptions none;
  none.level_resident = [](std::uint32_t) { return false; };
  ResidentScene rs(src, {0}, none);
  Scene s = make_scene(48, perspective());
  s.channels = {make_channel(0, kVisible, 0, 0)};
  const Rendered plain = render_cpu(rs, s);
  for (const glm::dmat3& axes : {glm::dmat3(1.0), rotation(30.0, 20.0)}) {
    Lens lens;
    lens.center = {0.45, 0.55, 0.5};
    lens.size = {0.2, 0.12, 0.16};
    lens.axes = axes;
    s.lens = lens;
    const Rendered r = render_cpu(rs, s);
    ASSERT_FALSE(r.bricks.empty());
    std::set<std::uint32_t> keys;
    for (const Request& q : r.bricks) {
      const PageAddress a = rs.decode(q.key);
      ASSERT_EQ(a.level, 0u);
      const auto [lo, hi] = brick_box(src.hierarchy(), 0, a.brick, 128.0);
      EXPECT_TRUE(box_meets_lens(lo, hi, lens))
          << "brick " << a.brick.x << "," << a.brick.y << "," << a.brick.z;
      keys.insert(q.key);
    }
    // The brick at the lens centre is seen through the lens.
    const glm::uvec3 centre(glm::floor(lens.center * 128.0 / 8.0));
    const std::uint32_t centre_key = rs.pages().device_key({0, 0, centre});
    EXPECT_TRUE(keys.count(centre_key) == 1u);
    EXPECT_LT(r.bricks.size() * 4, plain.bricks.size());
    EXPECT_EQ(r.stats.cap_hits, 0u);
  }
}

// Outside hidden: an orthographic view through a constant medium shows exactly the path length
// through lens ∩ volume as 1 - (1 - a)^(L / Δ₀), and the background elsewhere.
TEST(CpuLens, ClipsTheVolumeExactly) {
  ProceduralSource src("procedural:constant:32x32x32", bricks(8));
  ResidentScene rs(src, {0});
  const double a = 0.04;
  Scene s = make_scene(40, ortho_down_z(1.2));
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, a}}, {1.0, {1, 1, 1, a}}})};
  Lens lens;
  lens.center = {0.47, 0.52, 0.45};
  lens.size = {0.5, 0.3, 0.35};
  lens.axes = rotation(25.0, 35.0);
  s.lens = lens;
  const Rendered r = render_cpu(rs, s);
  const CameraRays rays(s.camera, s.viewport);
  std::uint32_t through = 0;
  for (std::uint32_t y = 0; y < 40; ++y) {
    for (std::uint32_t x = 0; x < 40; ++x) {
      const Ray ray = rays.pixel_ray(x, y);
      // Ray vs lens in lens coordinates, then vs the volume box [0, 1]^3, in double.
      const glm::dvec3 o = glm::transpose(lens.axes) * (ray.origin - lens.center);
      const glm::dvec3 d = glm::transpose(lens.axes) * ray.dir;
      Ray local{o, d};
      const glm::dvec2 tl = reference_ray_box(local, -0.5 * lens.size, 0.5 * lens.size);
      const glm::dvec2 tv = reference_ray_box(ray, glm::dvec3(0.0), glm::dvec3(1.0));
      const double len = std::max(0.0, std::min(tl.y, tv.y) - std::max({tl.x, tv.x, 0.0}));
      const double alpha = 1.0 - std::pow(1.0 - a, len * 32.0);
      if (len > 0.0) ++through;
      const glm::vec4 px = r.image.at(x, y);
      // Over a black opaque background: grey = alpha, alpha = 1.
      EXPECT_NEAR(px.r, alpha, 2e-4) << x << "," << y;
    }
  }
  EXPECT_GT(through, 200u);
  EXPECT_LT(through, 1400u);
}

// Outside at levels [2, 2]: a ray that misses the lens renders bit-identically to a plain scene
// whose channel is restricted to [2, 2] (with the same step), and with nothing resident requests
// level 2 outside and level 0 only for bricks meeting the lens.
TEST(CpuLens, OutsideRendersTheCoarserRange) {
  ProceduralSource src("procedural:sphere:64x64x64", bricks(8));
  ResidentScene all(src, {0});
  Scene s = make_scene(40, perspective());
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}, {1.0, {1, 0.6, 0.3, 0.4}}}, 0, 0)};
  s.step_scale = 0.5;
  Lens lens;
  lens.center = {0.55, 0.5, 0.5};
  lens.size = {0.2, 0.25, 0.2};
  lens.axes = rotation(15.0, 0.0);
  LensOutside coarse;
  coarse.channel = 0;
  coarse.hide = false;
  coarse.finest_level = 2;
  coarse.coarsest_level = 2;
  lens.outside = {coarse};
  s.lens = lens;
  const Rendered with_lens = render_cpu(all, s);

  Scene plain = s;
  plain.lens.reset();
  plain.channels[0].finest_level = 2;
  plain.channels[0].coarsest_level = 2;
  plain.step_scale = s.step_scale / 4.0;  // level 2's voxels are 4x larger: the same step
  const Rendered coarse_only = render_cpu(all, plain);

  const CameraRays rays(s.camera, s.viewport);
  std::uint32_t missing = 0, differing = 0;
  for (std::uint32_t y = 0; y < 40; ++y) {
    for (std::uint32_t x = 0; x < 40; ++x) {
      const Ray ray = rays.pixel_ray(x, y);
      const Ray local{glm::transpose(lens.axes) * (ray.origin - lens.center),
                      glm::transpose(lens.axes) * ray.dir};
      const glm::dvec2 tl = reference_ray_box(local, -0.5 * lens.size, 0.5 * lens.size);
      // Skip rays within rounding distance of the lens faces.
      if (tl.x < tl.y + 1e-4 && tl.y > -1e-4) {
        if (with_lens.image.at(x, y) != coarse_only.image.at(x, y)) ++differing;
        continue;
      }
      ++missing;
      EXPECT_EQ(with_lens.image.at(x, y), coarse_only.image.at(x, y)) << x << "," << y;
    }
  }
  EXPECT_GT(missing, 500u);
  EXPECT_GT(differing, 20u);  // inside, level 0 shows

  ResidentOptions none;
  none.level_resident = [](std::uint32_t) { return false; };
  ResidentScene cold(src, {0}, none);
  const Rendered r = render_cpu(cold, s);
  std::set<std::uint32_t> levels;
  for (const Request& q : r.bricks) {
    const PageAddress a = cold.decode(q.key);
    levels.insert(a.level);
    if (a.level == 0) {
      const auto [lo, hi] = brick_box(src.hierarchy(), 0, a.brick, 64.0);
      EXPECT_TRUE(box_meets_lens(lo, hi, lens));
    }
  }
  EXPECT_EQ(levels, (std::set<std::uint32_t>{0u, 2u}));
}

// The outside bank follows the slot table entry by entry: hidden channels are never visible,
// the level range is clamped to the hierarchy; a table whose size does not match is rejected.
TEST(CpuLens, FrameTablesHoldTheOutsideBank) {
  ProceduralSource src("procedural:ramp:32x32x32:3", bricks(8));
  ResidentScene rs(src, {0, 1, 2});
  Scene s = make_scene(8, perspective());
  s.channels = {make_channel(0, kVisible), make_channel(1, kVisible), make_channel(2, kVisible)};
  s.channels[2].importance = -1;  // slot-table entry 0
  Lens lens;
  LensOutside hide1;
  hide1.channel = 1;
  LensOutside coarse2;
  coarse2.channel = 2;
  coarse2.hide = false;
  coarse2.finest_level = 1;
  coarse2.coarsest_level = 20;
  lens.outside = {hide1, coarse2};  // channel 0 unlisted: hidden
  s.lens = lens;
  FrameTables t = rs.tables(s);
  ASSERT_EQ(t.frame.lens_enabled, 1u);
  ASSERT_EQ(t.slots.size(), 6u);
  const std::uint32_t last = src.hierarchy().level_count() - 1u;
  for (std::uint32_t k = 0; k < 3; ++k) {
    const kernel::ResoctSlotInfo& in = t.slots[k];
    const kernel::ResoctSlotInfo& out = t.slots[3 + k];
    EXPECT_EQ(out.slot, in.slot);
    if (in.slot == 2u) {
      EXPECT_EQ(out.vis_bins, in.vis_bins);
      EXPECT_EQ(out.finest_level, 1u);
      EXPECT_EQ(out.coarsest_level, last);
    } else {
      EXPECT_EQ(out.vis_bins, 0u);
      EXPECT_GT(out.vis_lo16, out.vis_hi16);
    }
  }
  EXPECT_EQ(t.slots[0].slot, 2u);
  cpu::CpuBackend backend(1);
  rs.upload(backend);
  t.slots.pop_back();
  FrameResult r;
  EXPECT_RESOCT_ERROR(backend.render(t, r), ErrorCode::invalid_argument,
                      "slot table size differs from slot_count");
}

// A lens roaming a 65536^3 volume (bricks of 256^3, 12 levels): with everything hidden outside,
// the renderer converges having paged in only bricks that meet the lens.
TEST(CpuLens, HugeVolumePagesOnlyTheNeighbourhood) {
  cpu::register_backend();
  std::shared_ptr<const BrickSource> source =
      make_procedural_source("procedural:constant:65536x65536x65536", bricks(256));
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.loader_threads = 0;
  o.strategy = RequestStrategy::global;  // only what is sampled, no coarser ancestors
  o.leaf_size = glm::uvec3(4096);
  o.device_cache_bytes = std::uint64_t(70) << 20;  // one 258^3 f32 slot; constant bricks need none
  Renderer renderer(source, o);
  Scene s = make_scene(24, Camera{});
  s.camera.eye = {0.503, 0.2532, 0.7012};
  s.camera.target = {0.5, 0.25, 0.7};
  s.step_scale = 8.0;
  s.channels = {make_channel(0, kVisible)};
  Lens lens;
  lens.center = {0.5, 0.25, 0.7};
  lens.size = glm::dvec3(0.002);  // 131 voxels
  s.lens = lens;
  const ConvergeReport rep = renderer.render_until_converged(s, 40);
  EXPECT_TRUE(rep.converged);
  EXPECT_EQ(rep.last.stats.backend.cap_hits, 0u);
  const PageTable& pages = inspect::page_table(renderer);
  const BrickHierarchy& h = renderer.hierarchy();
  std::uint32_t resident = 0;
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const glm::uvec3 nb = h.level(l).bricks;
    for (std::uint32_t local = 0; local < nb.x * nb.y * nb.z; ++local) {
      const glm::uvec3 b(local % nb.x, (local / nb.x) % nb.y, local / (nb.x * nb.y));
      if (kernel::resoct_page_state(pages.entry({0, l, b})) == kernel::RESOCT_PAGE_STATE_UNMAPPED) {
        continue;
      }
      ++resident;
      const auto [lo, hi] = brick_box(h, l, b, 65536.0);
      EXPECT_TRUE(box_meets_lens(lo, hi, lens)) << "level " << l;
    }
  }
  EXPECT_GT(resident, 0u);
  // The lens (131 voxels) straddles brick borders of the target level in x and y.
  EXPECT_LE(resident, 16u);
}

}  // namespace
}  // namespace resoct::test
