// The traversal kernel through the CPU backend against brute-force definitions: the reference
// renderer (double, exact TF, level 0), closed forms, and the three modes against each other.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "support/expect_error.hpp"
#include "resoct/scene/camera.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

// Tolerance of a reference match, per colour channel in [0, 1]: a small multiple (about three)
// of the error measured for that scene. The kernel runs in float, interpolates a 1024-entry LUT
// where the oracle evaluates the transfer function exactly, and samples with step 1/4 voxel
// instead of the oracle's 1/16; the two-channel scene also mixes its channels per step, which
// converges only at first order in the step. Measured (max, RMSE): sphere 1.4e-4, 1.6e-5; ramp
// 4.0e-5, 5.8e-6; two channels 1.1e-3, 3.9e-4.
struct RefTolerance {
  double max_abs;
  double rmse;
};

// Renders `spec` resident through the CPU backend and compares it with the reference renderer.
// Each tolerance must also be able to catch a bug: the same reference with every sample shifted
// by 0.1 voxel, or with 4 % more opacity, must fail it.
void expect_matches_reference(const std::string& spec, const Scene& scene,
                              std::vector<std::uint32_t> channels, RefTolerance tol) {
  ProceduralSource src(spec, bricks8());
  ResidentScene rs(src, channels);
  const Rendered r = render_cpu(rs, scene);
  const VolumeDesc& volume = src.hierarchy().volume();
  const VoxelFunction voxels = level0_voxels(src);
  const Image ref = render_reference(scene, volume, voxels);
  EXPECT_LT(max_diff(r.image, ref), tol.max_abs) << spec;
  EXPECT_LT(compare_images(r.image, ref).rmse_rgb, tol.rmse) << spec;
  EXPECT_EQ(r.stats.cap_hits, 0u);
  EXPECT_GT(r.stats.samples, 0u);
  EXPECT_TRUE(r.bricks.empty());
  ReferenceOptions shifted;
  shifted.sample_offset = glm::dvec3(0.1, 0.0, 0.0);
  ReferenceOptions opaque;
  opaque.opacity_scale = 1.04;
  for (const ReferenceOptions& bad : {shifted, opaque}) {
    const Image wrong = render_reference(scene, volume, voxels, bad);
    EXPECT_TRUE(max_diff(r.image, wrong) >= tol.max_abs ||
                compare_images(r.image, wrong).rmse_rgb >= tol.rmse)
        << spec << ": the tolerance does not catch a defective reference (offset "
        << bad.sample_offset.x << ", opacity x" << bad.opacity_scale << ")";
  }
}

TEST(CpuTraverse, ReferenceMatchSphere) {
  Scene s = make_scene(48, oblique_camera());
  s.channels = {make_channel(
      0, {{0.0, {1, 1, 1, 0}}, {0.3, {1, 0.6, 0.2, 0.05}}, {1.0, {0.2, 0.4, 1.0, 0.3}}}, 0, 0)};
  expect_matches_reference("procedural:sphere:32x32x32", s, {0}, {5e-4, 5e-5});
}

TEST(CpuTraverse, ReferenceMatchRamp) {
  Scene s = make_scene(48, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {0, 0, 0, 0}}, {1.0, {1, 0.5, 0.25, 0.1}}}, 0, 0)};
  expect_matches_reference("procedural:ramp:24x32x16", s, {0}, {1.5e-4, 2e-5});
}

TEST(CpuTraverse, ReferenceMatchTwoChannels) {
  Scene s = make_scene(40, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {1, 0, 0, 0}}, {1.0, {1, 0, 0, 0.08}}}, 0, 0),
                make_channel(1, {{0.0, {0, 0, 1, 0}}, {1.0, {0, 0.5, 1, 0.08}}}, 0, 0)};
  s.channels[1].importance = -1;  // traversed first; the image must not depend on it
  expect_matches_reference("procedural:ramp:24x24x24:2", s, {0, 1}, {2e-3, 6e-4});
}

// A constant medium of reference opacity a along an axis-parallel ray of length L voxels has
// opacity 1 − (1 − a)^L for every step and at every level.
TEST(CpuTraverse, ConstantBoxAnalytic) {
  ProceduralSource src("procedural:constant:32x32x32", bricks8());
  ResidentScene rs(src, {0});
  const double a = 0.05;
  for (std::uint32_t level : {0u, 2u}) {
    for (double step : {1.0 / 16.0, 0.25, 1.0, 4.0}) {
      Camera c;
      c.projection = Projection::orthographic;
      c.eye = {0.5, 0.5, 3.0};
      c.target = {0.5, 0.5, 0.0};
      c.ortho_height = 0.5;
      Scene s = make_scene(8, c);
      s.step_scale = step;
      s.ert_opacity = 1.0;
      s.channels = {make_channel(0, {{0.0, {1, 1, 1, a}}}, level, level)};
      const Rendered r = render_cpu(rs, s);
      // Level l voxels are 2^l level-0 voxels, but Δ₀ stays the finest level-0 voxel and the
      // step follows the finest allowed level: the optical depth per box unit is unchanged.
      const double expected_alpha = 1.0 - std::pow(1.0 - a, 32.0);
      // Over an opaque black background the pixel is white * alpha.
      for (const auto& p : r.image.pixels()) {
        ASSERT_NEAR(p.r, expected_alpha, 2e-4) << "level " << level << " step " << step;
      }
      EXPECT_EQ(r.stats.cap_hits, 0u);
    }
  }
}

// Trilinear sampling of a linear ramp is exact everywhere between the outermost voxel centres,
// including across brick borders (the halo). An opaque identity TF shows the first sample.
TEST(CpuTraverse, RampExactAcrossBrickBorders) {
  ProceduralSource src("procedural:ramp:64x8x8", bricks8());
  ResidentScene rs(src, {0});
  Camera c;
  c.projection = Projection::orthographic;
  c.eye = {0.5, 0.0625, 2.0};
  c.target = {0.5, 0.0625, 0.0};
  c.ortho_height = 1.0 / 256.0;  // 256 columns across the unit-wide box
  Scene s = make_scene(1);
  s.camera = c;
  s.viewport = {256, 1};
  s.ert_opacity = 1.0;
  s.channels = {make_channel(0, {{0.0, {0, 0, 0, 1}}, {1.0, {1, 1, 1, 1}}}, 0, 0)};
  const Rendered r = render_cpu(rs, s);
  const CameraRays rays(s.camera, s.viewport);
  for (std::uint32_t x = 0; x < 256; ++x) {
    const double vx = rays.pixel_ray(x, 0).origin.x * 64.0;  // voxel-space x
    const double expected = std::clamp(vx, 0.5, 63.5) / 64.0;
    ASSERT_NEAR(r.image.at(x, 0).r, expected, 2e-5) << "column " << x;
  }
}

Scene tubes_scene(std::uint32_t size) {
  Scene s = make_scene(size, oblique_camera());
  s.step_scale = 0.5;
  // A transparent plateau below 0.1: values there (the empty background) can be culled.
  s.channels = {make_channel(0,
                             {{0.0, {1, 1, 1, 0}},
                              {0.1, {1, 1, 1, 0}},
                              {0.2, {1, 0.8, 0.3, 0.1}},
                              {1.0, {1, 0.2, 0.1, 0.6}}},
                             0, 0)};
  return s;
}

TEST(CpuTraverse, ModesAgreeWhenResident) {
  ProceduralSource src("procedural:tubes:64x64x64", bricks8());
  ResidentScene rs(src, {0});
  const Scene s = tubes_scene(64);
  FrameOptions o;
  o.mode = RenderMode::residency;
  const Rendered res = render_cpu(rs, s, o);
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  o.mode = RenderMode::octree;
  const Rendered oc = render_cpu(rs, s, o);
  // Same sample positions (skips keep the step grid); only float summation order differs.
  EXPECT_LT(max_diff(res.image, pt.image), 1e-4);
  EXPECT_LT(max_diff(oc.image, pt.image), 1e-4);
  EXPECT_GT(res.stats.samples, 0u);
  for (const Rendered* r : {&res, &pt, &oc}) {
    EXPECT_EQ(r->stats.cap_hits, 0u);
    EXPECT_TRUE(r->bricks.empty());
  }
}

TEST(CpuTraverse, ResidencySkipsEmptySpace) {
  // 32³ bricks (the default) against 8³ octree leaves: the page table can only skip whole
  // EMPTY bricks, the residency octree skips every empty leaf and merges empty subtrees.
  ProceduralSource src("procedural:tubes:64x64x64", BrickLayout{});
  ResidentScene rs(src, {0});
  const Scene s = tubes_scene(48);
  FrameOptions o;
  const Rendered res = render_cpu(rs, s, o);
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  EXPECT_LT(max_diff(res.image, pt.image), 1e-4);
  // Iterations count every position the ray stops at (sampled or skipped from).
  EXPECT_LT(res.stats.iterations * 2, pt.stats.iterations)
      << res.stats.iterations << " vs " << pt.stats.iterations;
  EXPECT_GT(res.stats.distance_skipped, res.stats.distance_marched);
}

TEST(CpuTraverse, ImportanceOrderDoesNotChangeTheImage) {
  ProceduralSource src("procedural:tubes:32x32x32:3", bricks8());
  ResidentScene rs(src, {0, 1, 2});
  Scene s = make_scene(32, oblique_camera());
  for (std::uint32_t c = 0; c < 3; ++c) {
    s.channels.push_back(make_channel(
        c, {{0.0, {0, 0, 0, 0}}, {0.3, {c == 0 ? 1.0 : 0.2, c == 1 ? 1.0 : 0.2, 0.5, 0.2}}}, 0, 0));
  }
  const Rendered a = render_cpu(rs, s);
  s.channels[2].importance = -5;
  s.channels[0].importance = 3;
  const Rendered b = render_cpu(rs, s);
  EXPECT_LT(max_diff(a.image, b.image), 1e-5);
  EXPECT_GT(a.stats.samples, 0u);
}

// Only the coarsest level resident: residency mode substitutes it and requests the target;
// page-table mode renders nothing but requests; the standard octree uses the coarse brick.
TEST(CpuTraverse, MissingDataSubstitution) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  const std::uint32_t coarsest = src.hierarchy().level_count() - 1;
  ResidentOptions ro;
  ro.level_resident = [coarsest](std::uint32_t l) { return l == coarsest; };
  ResidentScene rs(src, {0}, ro);
  Scene s = make_scene(24, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0.4}}}, 0, coarsest)};
  const glm::vec4 bg(0, 0, 0, 1);
  FrameOptions o;
  const Rendered res = render_cpu(rs, s, o);
  EXPECT_FALSE(all_background(res.image, bg, 1e-3f));
  ASSERT_FALSE(res.bricks.empty());
  for (const Request& q : res.bricks) {
    EXPECT_LT(rs.decode(q.key).level, coarsest);
  }
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  EXPECT_TRUE(all_background(pt.image, bg));
  EXPECT_FALSE(pt.bricks.empty());
  EXPECT_EQ(pt.stats.samples, 0u);
  o.mode = RenderMode::octree;
  const Rendered oc = render_cpu(rs, s, o);
  EXPECT_FALSE(all_background(oc.image, bg, 1e-3f));
  EXPECT_FALSE(oc.bricks.empty());
}

// Greedy requests ask for every missing level between the target and the first present one.
TEST(CpuTraverse, GreedyRequestsCoarserLevels) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  const std::uint32_t coarsest = src.hierarchy().level_count() - 1;
  ASSERT_GE(coarsest, 2u);
  ResidentOptions ro;
  ro.level_resident = [coarsest](std::uint32_t l) { return l == coarsest; };
  ResidentScene rs(src, {0}, ro);
  Scene s = make_scene(16, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0.4}}}, 0, coarsest)};
  s.lod_error_px = 1e-3;  // target level 0 everywhere
  FrameOptions o;
  o.request_strategy = RequestStrategy::global;
  const Rendered global = render_cpu(rs, s, o);
  o.request_strategy = RequestStrategy::greedy;
  const Rendered greedy = render_cpu(rs, s, o);
  std::set<std::uint32_t> global_levels, greedy_levels;
  for (const Request& q : global.bricks) global_levels.insert(rs.decode(q.key).level);
  for (const Request& q : greedy.bricks) greedy_levels.insert(rs.decode(q.key).level);
  EXPECT_EQ(global_levels, std::set<std::uint32_t>{0u});
  std::set<std::uint32_t> expected;
  for (std::uint32_t l = 0; l < coarsest; ++l) expected.insert(l);
  EXPECT_EQ(greedy_levels, expected);
}

// Without metadata every node is INVALID: the traversal requests node metadata and still
// renders the same image (treated as not empty).
TEST(CpuTraverse, InvalidMetadataRequestsNodes) {
  ProceduralSource src("procedural:tubes:32x32x32", bricks8());
  ResidentOptions ro;
  ro.metadata = false;
  ResidentScene rs(src, {0}, ro);
  ResidentScene full(src, {0});
  const Scene s = tubes_scene(24);
  const Rendered no_meta = render_cpu(rs, s);
  const Rendered with_meta = render_cpu(full, s);
  EXPECT_FALSE(no_meta.nodes.empty());
  EXPECT_TRUE(with_meta.nodes.empty());
  EXPECT_LT(max_diff(no_meta.image, with_meta.image), 1e-4);
}

// Metadata only at a shallow depth: deeper nodes are INVALID (and requested), and a channel
// first classified there takes the class of its nearest ancestor with metadata. Channel 1's
// transfer function is visible only above 0.995, which the ramp never reaches, so with the
// carried class it is never sampled: the same bricks are read as with channel 0 alone.
TEST(CpuTraverse, InvalidNodesInheritTheNearestAncestorsClass) {
  ProceduralSource src("procedural:ramp:32x32x32:2", bricks8());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);
  ro.metadata_depth = 1;
  ResidentScene rs(src, {0, 1}, ro);
  ASSERT_GT(rs.layout().leaf_depth(), 1u);
  Scene one = make_scene(24, oblique_camera());
  one.channels = {
      make_channel(0, {{0.0, {1, 1, 1, 0}}, {0.5, {1, 1, 1, 0}}, {1.0, {1, 0.4, 0.1, 0.3}}}, 0, 0)};
  Scene two = one;
  two.channels.push_back(
      make_channel(1, {{0.0, {0, 0, 1, 0}}, {0.995, {0, 0, 1, 0}}, {1.0, {0, 0, 1, 1}}}, 0, 0));
  const Rendered r1 = render_cpu(rs, one);
  const Rendered r2 = render_cpu(rs, two);
  EXPECT_FALSE(r2.nodes.empty());
  EXPECT_GT(r1.stats.brick_accesses, 0u);
  EXPECT_EQ(r2.stats.brick_accesses, r1.stats.brick_accesses);
  EXPECT_LT(max_diff(r1.image, r2.image), 1e-6);
}

TEST(CpuTraverse, FrameTablesSlotOrderAndVisibility) {
  ProceduralSource src("procedural:ramp:16x16x16:3", bricks8());
  ResidentScene rs(src, {0, 1, 2});
  Scene s = make_scene(8, oblique_camera());
  s.channels = {
      make_channel(0, {{0.0, {1, 1, 1, 0}}, {0.5, {1, 1, 1, 0}}, {0.75, {1, 1, 1, 1}}}, 1, 3),
      make_channel(1, {{0.0, {1, 1, 1, 0}}}, 0, 3), make_channel(2, {{0.0, {1, 1, 1, 0.5}}}, 0, 3)};
  s.channels[0].importance = 1;
  s.channels[1].importance = 1;
  s.channels[2].importance = 2;
  const FrameTables t = rs.tables(s);
  ASSERT_EQ(t.slots.size(), 3u);
  // Equal importance: the finer finest level first.
  EXPECT_EQ(t.slots[0].slot, 1u);
  EXPECT_EQ(t.slots[1].slot, 0u);
  EXPECT_EQ(t.slots[2].slot, 2u);
  // Channel 0 is visible from the LUT cell left of 0.5 upwards: lo rounded down, hi up.
  EXPECT_LE(t.slots[1].vis_lo16, std::uint32_t(std::floor(0.5 * 65535.0)));
  EXPECT_GE(t.slots[1].vis_lo16, std::uint32_t(std::floor((0.5 - 1.0 / 1023.0) * 65535.0)));
  EXPECT_EQ(t.slots[1].vis_hi16, 65535u);
  // Fully transparent: never visible.
  EXPECT_GT(t.slots[0].vis_lo16, t.slots[0].vis_hi16);
  EXPECT_EQ(t.slots[0].vis_bins, 0u);
  EXPECT_EQ(t.levels.size(), src.hierarchy().level_count());
  EXPECT_EQ(t.depths.size(), rs.layout().depth_count());
  EXPECT_EQ(t.tf_luts.size(), 3u * 1024u);
}

TEST(CpuTraverse, FrameTablesRejectUnmappedChannel) {
  ProceduralSource src("procedural:ramp:16x16x16:3", bricks8());
  ResidentScene rs(src, {0});
  Scene s = make_scene(8, oblique_camera());
  s.channels = {make_channel(2, {{0.0, {1, 1, 1, 0.5}}})};
  EXPECT_RESOCT_ERROR(rs.tables(s), ErrorCode::invalid_argument, "channels");
  FrameOptions o;
  o.max_iterations = 0;
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0.5}}})};
  EXPECT_RESOCT_ERROR(rs.tables(s, o), ErrorCode::invalid_argument, "max_iterations");
}

// OpenMP tiles may run in any order on any thread: the image, statistics and requests must not
// depend on the thread count.
TEST(CpuTraverse, ThreadCountDoesNotChangeTheResult) {
  ProceduralSource src("procedural:sphere:32x32x32", bricks8());
  const std::uint32_t coarsest = src.hierarchy().level_count() - 1;
  ResidentOptions ro;
  ro.level_resident = [coarsest](std::uint32_t l) { return l != 0; };
  ResidentScene rs(src, {0}, ro);
  Scene s = make_scene(40, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0}}, {1.0, {1, 0.5, 0.2, 0.3}}}, 0, coarsest)};
  s.lod_error_px = 0.5;
  const FrameTables t = rs.tables(s);
  FrameResult one, four;
  cpu::CpuBackend b1(1), b4(4);
  rs.upload(b1);
  rs.upload(b4);
  b1.render(t, one);
  b4.render(t, four);
  b4.render(t, four);  // buffers reused across frames
  EXPECT_EQ(one.image, four.image);
  EXPECT_EQ(one.stats.samples, four.stats.samples);
  EXPECT_EQ(one.stats.iterations, four.stats.iterations);
  EXPECT_EQ(one.brick_requests, four.brick_requests);
  EXPECT_EQ(one.used_cache_slots, four.used_cache_slots);
  EXPECT_FALSE(one.brick_requests.empty());
  EXPECT_FALSE(one.used_cache_slots.empty());
}

TEST(CpuTraverse, BackendRejectsBadUpdatesAndTables) {
  ProceduralSource src("procedural:sphere:16x16x16", bricks8());
  ResidentScene rs(src, {0});
  cpu::CpuBackend b(1);
  rs.upload(b);
  std::vector<std::byte> voxels(10);
  BrickUpload up{0, voxels};
  FrameUpdate u;
  u.bricks = std::span<const BrickUpload>(&up, 1);
  EXPECT_RESOCT_ERROR(b.update(u), ErrorCode::invalid_argument, "update");
  PageDelta d{rs.pages().pool_block_count() * kernel::RESOCT_PAGE_BLOCK_ENTRIES, 0};
  FrameUpdate u2;
  u2.page_deltas = std::span<const PageDelta>(&d, 1);
  EXPECT_RESOCT_ERROR(b.update(u2), ErrorCode::invalid_argument, "update");
  // A directory word naming no pool block, and one outside the directory.
  for (const PageDelta bad : {PageDelta{0, rs.pages().pool_block_count()},
                              PageDelta{std::uint32_t(rs.pages().directory().size()), 0}}) {
    FrameUpdate u3;
    u3.directory_deltas = std::span<const PageDelta>(&bad, 1);
    EXPECT_RESOCT_ERROR(b.update(u3), ErrorCode::invalid_argument, "directory delta");
  }
  Scene s = make_scene(8, oblique_camera());
  s.channels = {make_channel(0, {{0.0, {1, 1, 1, 0.5}}})};
  FrameTables t = rs.tables(s);
  t.tf_luts.pop_back();
  FrameResult r;
  EXPECT_RESOCT_ERROR(b.render(t, r), ErrorCode::invalid_argument, "tables");
  // A sample shift of more than half a step back would start the march outside the volume.
  FrameTables j = rs.tables(s);
  j.frame.jitter_sample = -0.75f;
  EXPECT_RESOCT_ERROR(b.render(j, r), ErrorCode::invalid_argument, "jitter");
}

TEST(CpuTraverse, BackendRegistry) {
  cpu::register_backend();
  cpu::register_backend();
  auto b = create_backend("cpu");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->name(), "cpu");
}

}  // namespace
}  // namespace resoct::test
