// Error-bounded level of detail (Scene::lod_error_color, kernel/error_lod.glsl.h) on every
// backend. The level comes from the bricks' measured errors: the coarsest level whose brick is
// fine enough for the transfer function, coarser or finer than the footprint's target, with the
// footprint's step and its culling of EMPTY bricks. Checked at the limits, bit for bit against
// scenes forced to one level with the same step: a colour error no brick meets gives the finest
// level everywhere, one every coarse brick meets gives the coarsest; and the three render modes
// agree where a coarse level smears values into nodes that are empty at level 0.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "backend_test_util.hpp"
#include "cpu/cpu_test_util.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/sources/metadata_pyramid.hpp"
#include "resoct/volume/dense_volume.hpp"

namespace resoct::test {
namespace {

namespace k = resoct::kernel;

// A 64³ f32 volume in 16³ bricks whose voxel (x, y, z) holds value(x, y, z): 64³ has levels 0..2
// and level 2 is one brick.
template <class Source, class Value>
Source volume64(Value value) {
  VolumeDesc d;
  d.extent = glm::u64vec3(64);
  d.type = VoxelType::f32;
  std::vector<float> v(64 * 64 * 64);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(value(i % 64, i / 64 % 64, i / 4096));
  BrickLayout l;
  l.brick_size = glm::uvec3(16);
  return Source(DenseVolume::from_values(d, v), l);
}

// A smooth bump, b(r) = max(0, 1 - (r / 12)²)², r in voxels from near the centre, over a floor
// `floor` (0: empty space around it).
InMemorySource blob(float floor) {
  return volume64<InMemorySource>([floor](std::size_t x, std::size_t y, std::size_t z) {
    const glm::dvec3 p{double(x), double(y), double(z)};
    const double r = glm::length(p + 0.5 - glm::dvec3(30.0, 33.0, 31.0)) / 12.0;
    const double b = r < 1.0 ? (1.0 - r * r) * (1.0 - r * r) : 0.0;
    return floor + (1.0 - floor) * b;
  });
}

// An in-memory source whose region metadata is exact to the voxel (the in-memory pyramid's
// blocks are at least 4³), as the renderer's leaves are once their level-0 brick is scanned.
class ExactMetaSource : public InMemorySource {
 public:
  using InMemorySource::InMemorySource;
  RegionMeta region_meta(std::uint32_t channel, const Box3& region) const override {
    const VolumeDesc& v = volume();
    const glm::i64vec3 e(v.extent);
    const glm::i64vec3 lo = glm::clamp(region.lo, glm::i64vec3(0), e);
    const glm::i64vec3 hi = glm::clamp(region.hi, glm::i64vec3(0), e);
    const std::span<const std::byte> all = level_voxels(0, channel);
    RegionMeta m;
    for (std::int64_t z = lo.z; z < hi.z; ++z)
      for (std::int64_t y = lo.y; y < hi.y; ++y)
        for (std::int64_t x = lo.x; x < hi.x; ++x) {
          const std::size_t i = std::size_t(x + e.x * (y + e.y * z));
          m.merge(scan_region(all.subspan(i * voxel_size(v.type), voxel_size(v.type)), v.type,
                              v.range(channel)));
        }
    return m;
  }
};

// A ramp along x, v = clamp((38 - x) / 16, 0, 1) at voxel centres x, in 16³ bricks: it ends at
// x = 38, so the 8³ octree nodes from x = 40 on are empty at level 0 (their records cover one
// voxel more), while level 2's voxel [36, 40) averages the ramp's last values and its
// reconstruction reaches into them.
ExactMetaSource wedge() {
  return volume64<ExactMetaSource>([](std::size_t x, std::size_t, std::size_t) {
    return std::clamp((38.0 - (double(x) + 0.5)) / 16.0, 0.0, 1.0);
  });
}

// Along x: a smooth part that ends with 0.5 at x = 14 (level 1 reconstructs it within 1/4, and
// smears 0.06 into x = 16), zeros from 15 to 49, and a checkerboard from 50 on (no coarse level
// within 1/4 there). Seen along -x, the march enters the empty nodes from the checkerboard's
// side, where level 0 is chosen (level-1 brick x >= 32) and a skip may run on through the empty
// nodes, into level-1 brick x < 32, where level 1 is chosen and smears into its empty nodes.
ExactMetaSource edge_and_checker() {
  return volume64<ExactMetaSource>([](std::size_t x, std::size_t y, std::size_t z) {
    if (x < 4) return 1.0;
    if (x <= 14) return 1.0 - 0.5 * double(x - 4) / 10.0;
    return x >= 50 && (x + y + z) % 2 == 0 ? 1.0 : 0.0;
  });
}

ResidentScene with_errors(const BrickSource& src) {
  ResidentOptions o;
  o.brick_errors = true;
  return ResidentScene(src, {0}, o);
}

// `faint`: a transfer function that shows the faint values a coarse level smears past the
// bump's edge; otherwise a soft ramp. Both are transparent up to 0.01, so empty space is culled.
Scene blob_scene(bool faint) {
  Camera cam;
  cam.eye = {0.5, 0.62, 1.7};
  cam.target = {0.5, 0.5, 0.5};
  Scene s = make_scene(48, cam);
  s.lod_error_px = 0.5;  // level 0 everywhere by the footprint alone
  s.channels = {faint ? make_channel(0, {{0.0, {1, 1, 1, 0}},
                                         {0.01, {1, 1, 1, 0}},
                                         {0.11, {1, 0.6, 0.2, 0.3}},
                                         {1.0, {0.2, 0.5, 1.0, 0.3}}})
                      : make_channel(0, {{0.0, {1, 1, 1, 0}},
                                         {0.01, {1, 1, 1, 0}},
                                         {0.4, {1, 0.5, 0.2, 0.1}},
                                         {1.0, {0.2, 0.5, 1.0, 0.4}}})};
  return s;
}

// The error codes of the coarse (level >= 1) entries of slot 0 that hold data.
std::pair<std::uint32_t, std::uint32_t> coarse_code_range(const ResidentScene& rs) {
  const BrickHierarchy& h = rs.hierarchy();
  std::uint32_t lo = 15, hi = 0;
  for (std::uint32_t l = 1; l < h.level_count(); ++l) {
    const glm::uvec3 n = h.level(l).bricks;
    for (std::uint32_t z = 0; z < n.z; ++z)
      for (std::uint32_t y = 0; y < n.y; ++y)
        for (std::uint32_t x = 0; x < n.x; ++x) {
          const std::uint32_t e = rs.pages().entry({0, l, {x, y, z}});
          const std::uint32_t state = k::resoct_page_state(e);
          if (state != k::RESOCT_PAGE_STATE_MAPPED && state != k::RESOCT_PAGE_STATE_HOMOGENEOUS)
            continue;
          lo = std::min(lo, k::resoct_page_error_code(e));
          hi = std::max(hi, k::resoct_page_error_code(e));
        }
  }
  return {lo, hi};
}

// The largest colour error 2^-j (at most 1, the scene's limit) whose slot code (from the frame
// tables) is `code`, or -1 when none is: the code grows by one per halving.
double colour_for_code(const ResidentScene& rs, Scene s, std::uint32_t code) {
  for (int j = 0; j <= 40; ++j) {
    s.lod_error_color = std::ldexp(1.0, -j);
    if (rs.tables(s).slots[0].lod_error_code == code) return s.lod_error_color;
  }
  return -1.0;
}
// The largest such colour error whose code is at most `code` (every brick with `code` meets it).
double colour_at_most(const ResidentScene& rs, Scene s, std::uint32_t code) {
  s.lod_error_color = 1.0;
  return rs.tables(s).slots[0].lod_error_code <= code ? 1.0 : -1.0;
}

// `s` forced to level `level` alone, with the step of a scene whose step follows `step_level`
// (the march's step follows the finest level a channel may sample; the two steps are the same
// float, since they differ by a power of two).
Scene forced(const ResidentScene& rs, Scene s, std::uint32_t level, std::uint32_t step_level) {
  const glm::uvec3 f = rs.hierarchy().level(level).factor_log2;
  const glm::uvec3 g = rs.hierarchy().level(step_level).factor_log2;
  EXPECT_TRUE(f.x == f.y && f.y == f.z && g.x == g.y && g.y == g.z);
  s.channels[0].finest_level = level;
  s.channels[0].coarsest_level = level;
  s.step_scale = std::ldexp(s.step_scale, int(g.x) - int(f.x));
  s.lod_error_color = 0.0;
  return s;
}

class BackendErrorLod : public BackendTest {
 protected:
  void expect_same(const ResidentScene& rs, const Scene& a, const Scene& b, const char* what) {
    for (RenderMode m : {RenderMode::pagetable, RenderMode::residency, RenderMode::octree}) {
      FrameOptions o;
      o.mode = m;
      const Rendered ra = render(rs, a, o);
      const Rendered rb = render(rs, b, o);
      EXPECT_EQ(max_diff(ra.image, rb.image), 0.0) << what << ", mode " << to_string(m);
      EXPECT_EQ(ra.stats.cap_hits, 0u);
    }
  }
};

TEST_P(BackendErrorLod, OffGivesTheFootprintImageWithErrorCodesInTheEntries) {
  const InMemorySource src = blob(0.0f);
  const ResidentScene plain(src, {0});
  const ResidentScene coded = with_errors(src);
  ASSERT_GT(coarse_code_range(coded).second, 0u)
      << "the coarse entries must carry error codes for this test to mean anything";
  for (bool faint : {false, true}) {
    const Scene s = blob_scene(faint);
    for (RenderMode m : {RenderMode::residency, RenderMode::pagetable, RenderMode::octree}) {
      FrameOptions o;
      o.mode = m;
      const Rendered a = render(plain, s, o);
      const Rendered b = render(coded, s, o);
      EXPECT_EQ(max_diff(a.image, b.image), 0.0) << to_string(m);
      EXPECT_EQ(a.stats.samples, b.stats.samples) << to_string(m);
      EXPECT_EQ(a.stats.brick_accesses, b.stats.brick_accesses) << to_string(m);
      EXPECT_EQ(a.stats.nodes_visited, b.stats.nodes_visited) << to_string(m);
    }
  }
}

TEST_P(BackendErrorLod, TheLimitsAreTheFinestAndTheCoarsestLevel) {
  // On a floor of 0.05 no brick is EMPTY, so the footprint's culling does not come into it.
  const InMemorySource src = blob(0.05f);
  const ResidentScene rs = with_errors(src);
  const auto [lo, hi] = coarse_code_range(rs);
  ASSERT_GE(lo, 1u) << "every coarse brick of a smooth field has a measured error below 1/2";
  ASSERT_LT(hi, 15u);
  const std::uint32_t top = rs.hierarchy().level_count() - 1;
  ASSERT_EQ(rs.hierarchy().level(top).brick_count, 1u);
  for (bool faint : {false, true}) {
    SCOPED_TRACE(faint ? "faint values shown" : "soft ramp");
    const Scene base = blob_scene(faint);
    // No coarse brick meets it: level 0 everywhere, which the footprint also picks here.
    Scene none = base;
    none.lod_error_color = colour_for_code(rs, base, hi + 1);
    ASSERT_GT(none.lod_error_color, 0.0);
    expect_same(rs, none, base, "none");
    // Every coarse brick meets it: the search starts at the coarsest level, one brick.
    Scene all = base;
    all.lod_error_color = colour_at_most(rs, base, lo);
    ASSERT_GT(all.lod_error_color, 0.0);
    const Scene coarsest = forced(rs, base, top, 0);
    expect_same(rs, all, coarsest, "all");
    // Finer than the footprint: at 8 px the footprint picks the coarsest level (and its
    // step); with a colour error no coarse brick meets, level 0 is sampled at that step.
    Scene far = base;
    far.lod_error_px = 8.0;
    ASSERT_EQ(rs.tables(far).frame.finest_voxel_x, rs.tables(coarsest).frame.finest_voxel_x);
    Scene refined = far;
    refined.lod_error_color = none.lod_error_color;
    expect_same(rs, refined, forced(rs, base, 0, top), "refined");
    // In between: some bricks coarsened, some not, and the image between the limits.
    if (hi > lo) {
      Scene mid = base;
      mid.lod_error_color = colour_for_code(rs, base, hi);
      const Rendered m = render(rs, mid);
      const Rendered f = render(rs, base);
      const Rendered c = render(rs, coarsest);
      EXPECT_GT(max_diff(m.image, f.image), 0.0);
      EXPECT_GT(max_diff(m.image, c.image), 0.0);
      EXPECT_LT(compare_images(m.image, f.image).rmse_rgb,
                compare_images(c.image, f.image).rmse_rgb);
    }
  }
}

TEST_P(BackendErrorLod, ModesAgreeWhereACoarseLevelSmearsIntoEmptyNodes) {
  // The coarse level's reconstruction reaches past the ramp's end into nodes that are empty at
  // level 0; residency mode may cull there only with the margin of the coarsest level the
  // channel may sample. The page table culls EMPTY level-0 bricks only.
  const ExactMetaSource src = wedge();
  const ResidentScene rs = with_errors(src);
  const auto [lo, hi] = coarse_code_range(rs);
  // Without early termination the samples a frame takes are what culling leaves.
  Scene faint = blob_scene(true);
  faint.ert_opacity = 1.0;
  const std::uint32_t least = rs.tables(faint).slots[0].lod_error_code;  // at colour error 1
  ASSERT_LE(least, hi) << "some coarse brick must meet the coarsest colour error";
  for (std::uint32_t code = std::max(lo, least); code <= hi; ++code) {
    Scene s = faint;
    s.lod_error_color = colour_for_code(rs, s, code);
    ASSERT_GT(s.lod_error_color, 0.0);
    FrameOptions o;
    o.mode = RenderMode::pagetable;
    const Rendered pt = render(rs, s, o);
    const Rendered footprint = render(rs, faint, o);
    EXPECT_GT(max_diff(pt.image, footprint.image), 1e-3)
        << "code " << code << ": error-bounded LOD must change this image";
    for (RenderMode m : {RenderMode::residency, RenderMode::octree}) {
      o.mode = m;
      const Rendered r = render(rs, s, o);
      EXPECT_LE(max_diff(r.image, pt.image), 1e-6) << to_string(m) << ", code " << code;
      EXPECT_LE(r.stats.samples, pt.stats.samples) << to_string(m) << ", code " << code;
    }
  }
}

TEST_P(BackendErrorLod, ASkipStopsWhereAnotherLevelIsChosen) {
  // Residency mode's culling holds only where the levels it assumed are chosen: a skip that
  // starts where level 0 is chosen (no margin) must not run on into a brick that chooses level
  // 1, whose reconstruction reaches into the empty nodes there.
  const ExactMetaSource src = edge_and_checker();
  const ResidentScene rs = with_errors(src);
  Scene s = blob_scene(true);
  s.camera.eye = {1.8, 0.52, 0.47};
  s.ert_opacity = 1.0;
  s.lod_error_color = 1.0;
  ASSERT_EQ(rs.tables(s).slots[0].lod_error_code, 2u);
  FrameOptions o;
  o.mode = RenderMode::pagetable;
  const Rendered pt = render(rs, s, o);
  EXPECT_GT(max_diff(pt.image, render(rs, blob_scene(true), o).image), 1e-3)
      << "error-bounded LOD must change this image";
  for (RenderMode m : {RenderMode::residency, RenderMode::octree}) {
    o.mode = m;
    const Rendered r = render(rs, s, o);
    EXPECT_LE(max_diff(r.image, pt.image), 1e-6) << to_string(m);
    EXPECT_EQ(r.stats.cap_hits, 0u);
  }
}

TEST_P(BackendErrorLod, AMissingLevelOnTheWayDownIsRequested) {
  // Level 1 is not resident. With a colour error no coarse brick meets, the search passes level
  // 2 and stops at level 1, which is requested (a view refines level by level as bricks and
  // their errors arrive); level 0, resident, is not reached.
  const InMemorySource src = blob(0.05f);
  ResidentOptions o;
  o.brick_errors = true;
  o.level_resident = [](std::uint32_t l) { return l != 1; };
  const ResidentScene rs(src, {0}, o);
  Scene s = blob_scene(false);
  s.lod_error_color = colour_for_code(rs, s, coarse_code_range(rs).second + 1);
  ASSERT_GT(s.lod_error_color, 0.0);
  for (RenderMode m : {RenderMode::pagetable, RenderMode::residency, RenderMode::octree}) {
    FrameOptions fo;
    fo.mode = m;
    const Rendered r = render(rs, s, fo);
    ASSERT_FALSE(r.bricks.empty()) << to_string(m);
    for (const Request& q : r.bricks) EXPECT_EQ(rs.decode(q.key).level, 1u) << to_string(m);
  }
}

INSTANTIATE_TEST_SUITE_P(ErrorLod, BackendErrorLod, ::testing::ValuesIn(test_backends()),
                         backend_param_name);

}  // namespace
}  // namespace resoct::test
