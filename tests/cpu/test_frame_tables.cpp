// build_frame_tables against the double-precision camera (CameraRays) and hierarchy: the
// kernel's per-pixel rays, the exact eye split and the sampling constants.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "resoct/scene/camera.hpp"
#include "resoct/render/frame_tables.hpp"
#include "resoct/kernel/camera_ray.glsl.h"

namespace resoct {
namespace {

struct Fixture {
  BrickHierarchy hierarchy;
  OctreeLayout layout;
  PageTable pages;
  ChannelMap channels;
  explicit Fixture(VolumeDesc v)
      : hierarchy(v, BrickLayout{}),
        layout(v.extent, glm::uvec3(16)),
        pages(hierarchy, 1, 16),
        channels(1, v.channels) {
    channels.assign(0, 0, pages);
  }
};

Scene scene_with(Camera c, Viewport vp) {
  Scene s;
  s.camera = c;
  s.viewport = vp;
  ChannelSettings ch;
  ch.tf = TransferFunction({{0.0, {1, 1, 1, 0.5}}});
  s.channels = {ch};
  return s;
}

TEST(FrameTables, KernelRaysMatchCameraRays) {
  VolumeDesc v;
  v.extent = {200, 120, 64};
  v.spacing = {1.0, 1.5, 2.0};
  Fixture fx(v);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  for (Projection p : {Projection::perspective, Projection::orthographic}) {
    for (int trial = 0; trial < 8; ++trial) {
      Camera c;
      c.projection = p;
      c.eye = {u(rng) + 1.5, u(rng), u(rng) - 1.5};
      c.target = {0.5, 0.3, 0.2};
      c.fov_deg = 25.0 + 10.0 * trial;
      c.ortho_height = 0.3 + 0.2 * trial;
      const Viewport vp{37, 23};
      const FrameTables t =
          build_frame_tables(scene_with(c, vp), fx.hierarchy, fx.layout, fx.channels);
      const CameraRays rays(c, vp);
      EXPECT_NEAR(t.frame.footprint_base, rays.footprint_base(), 1e-7);
      EXPECT_NEAR(t.frame.footprint_slope, rays.footprint_slope(), 1e-7);
      const glm::dvec3 per_box = 1.0 / box_voxel_size(v);
      for (std::uint32_t y = 0; y < vp.height; y += 5) {
        for (std::uint32_t x = 0; x < vp.width; x += 4) {
          glm::vec3 dir;
          glm::ivec3 cell;
          glm::vec3 frac;
          kernel::resoct_camera_ray(t.frame, x, y, dir, cell, frac);
          const Ray r = rays.pixel_ray(x, y);
          for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(dir[i], r.dir[i], 2e-6);
            EXPECT_GE(frac[i], 0.0f);
            EXPECT_LT(frac[i], 1.0f);
            const double origin_vox = double(cell[i]) + double(frac[i]);
            EXPECT_NEAR(origin_vox, r.origin[i] * per_box[i], 1e-4 * (1.0 + per_box[i]));
          }
        }
      }
    }
  }
}

// The eye's cell is exact even where a float could not hold the voxel coordinate.
TEST(FrameTables, EyeSplitIsExactOnHugeAxes) {
  VolumeDesc v;
  v.extent = {std::uint64_t(1) << 20, 4, 4};
  Fixture fx(v);
  Camera c;
  c.eye = {0.7300001234, 0.5 / double(1 << 20), 2.0 / double(1 << 20)};
  c.target = {0.2, 0.5 / double(1 << 20), 2.0 / double(1 << 20)};
  const FrameTables t =
      build_frame_tables(scene_with(c, {8, 8}), fx.hierarchy, fx.layout, fx.channels);
  const double ex = c.eye.x * double(1 << 20);
  EXPECT_EQ(t.frame.eye_cell_x, int(std::floor(ex)));
  EXPECT_NEAR(t.frame.eye_frac_x, ex - std::floor(ex), 1e-6);
  EXPECT_EQ(t.frame.eye_cell_y, 0);
  EXPECT_NEAR(t.frame.eye_frac_y, 0.5, 1e-6);
  EXPECT_EQ(t.frame.eye_cell_z, 2);
}

TEST(FrameTables, SamplingConstants) {
  VolumeDesc v;
  v.extent = {64, 64, 16};
  v.spacing = {1.0, 1.0, 4.0};
  Fixture fx(v);
  Scene s = scene_with(Camera{}, {16, 16});
  s.channels[0].finest_level = 1;
  s.channels[0].coarsest_level = kMaxSceneLevel;
  s.step_scale = 0.5;
  const FrameTables t = build_frame_tables(s, fx.hierarchy, fx.layout, fx.channels);
  const glm::dvec3 h1 = level_voxel_size(fx.hierarchy, 1);
  EXPECT_FLOAT_EQ(t.frame.finest_voxel_x, float(h1.x));
  EXPECT_FLOAT_EQ(t.frame.finest_voxel_z, float(h1.z));
  EXPECT_FLOAT_EQ(t.frame.ref_step, float(reference_step_length(v)));
  EXPECT_EQ(t.slots[0].coarsest_level, fx.hierarchy.level_count() - 1);
  EXPECT_EQ(t.slots[0].finest_level, 1u);
  const std::vector<float> sizes = level_size_log2_table(fx.hierarchy);
  for (std::uint32_t l = 0; l < fx.hierarchy.level_count(); ++l) {
    EXPECT_EQ(t.levels[l].size_log2, sizes[l]);
    EXPECT_EQ(t.levels[l].bricks_x, fx.hierarchy.level(l).bricks.x);
  }
  for (std::uint32_t d = 0; d < fx.layout.depth_count(); ++d) {
    EXPECT_EQ(t.depths[d].first_node, fx.layout.depth(d).first_node);
    EXPECT_EQ(t.depths[d].node_extent_z, fx.layout.depth(d).node_extent.z);
  }
  EXPECT_GT(t.frame.min_step, 0.0f);
  EXPECT_LT(t.frame.min_step, 1e-3f * t.frame.ref_step);
}

// The residency traversal's depth rules, tabled per frame (render/traversal_depths.hpp): each
// depth's shortest node side in box units, and per level the deepest depth (from start_depth on)
// whose nodes span two of its voxels per axis, spelt out here from the layout.
TEST(FrameTables, TraversalDepthRulesAreTabledPerDepthAndLevel) {
  VolumeDesc v;
  v.extent = {1024, 512, 128};
  v.spacing = {1.0, 1.0, 4.0};
  Fixture fx(v);
  FrameOptions options;
  options.start_depth = 1;
  const FrameTables t = build_frame_tables(scene_with(Camera{}, {16, 16}), fx.hierarchy, fx.layout,
                                           fx.channels, options);
  const std::uint32_t depths = fx.layout.depth_count();
  ASSERT_GE(depths, 4u);
  for (std::uint32_t d = 0; d < depths; ++d) {
    const glm::u64vec3 ne = fx.layout.depth(d).node_extent;
    const float side =
        std::min({float(ne.x) / t.frame.voxels_per_box_x, float(ne.y) / t.frame.voxels_per_box_y,
                  float(ne.z) / t.frame.voxels_per_box_z});
    EXPECT_EQ(t.depths[d].shortest_side, side) << "depth " << d;
  }
  std::uint32_t distinct = 0;
  for (std::uint32_t l = 0; l < fx.hierarchy.level_count(); ++l) {
    const glm::uvec3 f = fx.hierarchy.level(l).factor_log2;
    std::uint32_t cap = 1;
    while (cap + 1 < depths) {
      const glm::u64vec3 ne = fx.layout.depth(cap + 1).node_extent;
      if ((ne.x >> f.x) < 2 || (ne.y >> f.y) < 2 || (ne.z >> f.z) < 2) break;
      ++cap;
    }
    EXPECT_EQ(t.levels[l].depth_cap, cap) << "level " << l;
    if (l > 0 && t.levels[l].depth_cap != t.levels[l - 1].depth_cap) ++distinct;
  }
  EXPECT_EQ(t.levels[0].depth_cap, depths - 1) << "level 0: every depth's nodes span two voxels";
  EXPECT_GT(distinct, 0u) << "the volume should give coarse levels shallower caps";
}

// The step follows the finest level any sample can pick (docs/rendering.md, "Step size"):
// brute force over a grid of points in the volume, each point's level by the LOD rule's
// definition (coarsest level whose voxel fits the pixel footprint at its view depth).
std::uint32_t step_level(const FrameTables& t, const BrickHierarchy& h) {
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    if (float(level_voxel_size(h, l).x) == t.frame.finest_voxel_x) return l;
  }
  ADD_FAILURE() << "finest_voxel_x matches no level";
  return 0;
}

std::uint32_t finest_level_picked(const Scene& s, const BrickHierarchy& h) {
  const CameraRays rays(s.camera, s.viewport);
  const glm::dvec3 ext = box_extent(h.volume());
  const std::vector<float> sizes = level_size_log2_table(h);
  std::uint32_t finest = ~0u;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 8; ++j) {
      for (int k = 0; k <= 8; ++k) {
        const glm::dvec3 p = ext * glm::dvec3(i, j, k) / 8.0;
        const double depth = glm::dot(p - s.camera.eye, rays.forward());
        const double budget = std::log2(rays.footprint(depth) * s.lod_error_px);
        std::uint32_t level = 0;
        for (std::uint32_t l = 1; l < sizes.size() && double(sizes[l]) <= budget; ++l) level = l;
        finest = std::min(finest, level);
      }
    }
  }
  return finest;
}

TEST(FrameTables, StepFollowsTheFinestLevelAnySampleCanPick) {
  VolumeDesc v;
  v.extent = {1024, 1024, 1024};
  Fixture fx(v);
  Camera far;
  far.eye = {0.5, 0.5, 3.0};
  Scene s = scene_with(far, {64, 64});
  s.channels[0].coarsest_level = kMaxSceneLevel;
  const FrameTables t = build_frame_tables(s, fx.hierarchy, fx.layout, fx.channels);
  const std::uint32_t picked = finest_level_picked(s, fx.hierarchy);
  ASSERT_GE(picked, 2u) << "the far view must be coarse for this test to mean anything";
  ASSERT_LT(picked + 1, fx.hierarchy.level_count()) << "room for a coarser finest level";
  // Never coarser than a sample needs; at most one level finer (the 1e-3 rounding margin).
  EXPECT_LE(step_level(t, fx.hierarchy), picked);
  EXPECT_GE(step_level(t, fx.hierarchy) + 1, picked);

  // A channel's own range still bounds the step level: finer than allowed never, coarser than
  // its coarsest never.
  s.channels[0].finest_level = picked + 1;
  EXPECT_EQ(step_level(build_frame_tables(s, fx.hierarchy, fx.layout, fx.channels), fx.hierarchy),
            picked + 1);
  s.channels[0].finest_level = 0;
  s.channels[0].coarsest_level = 1;
  EXPECT_EQ(step_level(build_frame_tables(s, fx.hierarchy, fx.layout, fx.channels), fx.hierarchy),
            1u);

  // A camera inside the volume can pick level 0, so the step is level 0's.
  Camera inside;
  inside.eye = {0.5, 0.5, 0.5};
  inside.target = {0.5, 0.5, 0.0};
  Scene near = scene_with(inside, {64, 64});
  near.channels[0].coarsest_level = kMaxSceneLevel;
  EXPECT_EQ(
      step_level(build_frame_tables(near, fx.hierarchy, fx.layout, fx.channels), fx.hierarchy), 0u);
}

// Frame tables built into the same FrameTables frame after frame (as Renderer does) recompute a
// LUT only where its transfer function changed, and equal a fresh build after every change: a
// camera move, one transfer function, pre-integration on and off, a channel hidden and shown.
TEST(FrameTables, ReusedTablesRecomputeOnlyChangedLutsAndEqualAFreshBuild) {
  VolumeDesc v;
  v.extent = {64, 48, 40};
  v.channels = 3;
  const BrickHierarchy hierarchy(v, BrickLayout{});
  const OctreeLayout layout(v.extent, glm::uvec3(16));
  PageTable pages(hierarchy, 3, 16);
  ChannelMap channels(3, 3);
  for (std::uint32_t c = 0; c < 3; ++c) channels.assign(c, c, pages);
  Camera cam;
  cam.eye = {1.8, 1.1, 1.6};
  Scene s = scene_with(cam, {32, 24});
  s.channels.clear();
  for (std::uint32_t c = 0; c < 3; ++c) {
    ChannelSettings ch;
    ch.channel = c;
    ch.tf =
        TransferFunction({{0.1 * c, {1, 0, 0, 0}}, {0.5 + 0.1 * c, {0, 1, 0.5, 0.3 + 0.2 * c}}});
    s.channels.push_back(ch);
  }
  FrameTables reused;
  std::uint64_t version = 0;
  // `luts`: transfer-function LUTs recomputed; the step levels' LUTs (and their version, which a
  // device copy follows) change exactly when some shown slot's LUT or the shown slots change.
  const auto expect_fresh = [&](const char* step, std::uint32_t luts,
                                bool step_luts_change = true) {
    build_frame_tables(s, hierarchy, layout, channels, {}, reused);
    const FrameTables fresh = build_frame_tables(s, hierarchy, layout, channels, {});
    EXPECT_EQ(reused.luts_built, luts) << step;
    EXPECT_EQ(fresh.luts_built, std::uint32_t(s.channels.size())) << step;
    EXPECT_EQ(reused.tf_luts, fresh.tf_luts) << step;
    EXPECT_EQ(reused.preint_tables, fresh.preint_tables) << step;
    EXPECT_GT(reused.frame.step_level_count, 0u) << step;
    EXPECT_EQ(reused.step_luts, fresh.step_luts) << step;
    EXPECT_EQ(reused.step_luts_version != version, step_luts_change) << step;
    EXPECT_NE(fresh.step_luts_version, reused.step_luts_version) << step;
    version = reused.step_luts_version;
    ASSERT_EQ(reused.slots.size(), fresh.slots.size()) << step;
    EXPECT_EQ(std::memcmp(reused.slots.data(), fresh.slots.data(),
                          fresh.slots.size() * sizeof(kernel::ResoctSlotInfo)),
              0)
        << step;
    EXPECT_EQ(std::memcmp(&reused.frame, &fresh.frame, sizeof(fresh.frame)), 0) << step;
  };
  expect_fresh("first build", 3);
  s.camera.eye = {1.7, 1.2, 1.5};
  expect_fresh("camera moved", 0, false);
  s.channels[1].tf = TransferFunction({{0.2, {0, 0, 1, 0}}, {0.9, {1, 1, 1, 0.8}}});
  expect_fresh("one transfer function changed", 1);
  s.preintegration = true;
  expect_fresh("pre-integration on", 0, false);
  s.camera.eye = {1.6, 1.2, 1.5};
  expect_fresh("camera moved with pre-integration", 0, false);
  s.channels[0].tf = TransferFunction({{0.0, {1, 1, 0, 0}}, {1.0, {1, 1, 0, 0.5}}});
  expect_fresh("transfer function changed with pre-integration", 1);
  const ChannelSettings hidden = s.channels[2];
  s.channels.pop_back();
  expect_fresh("channel 2 hidden", 0);
  EXPECT_FALSE(reused.lut_sources[2].has_value());
  s.channels.push_back(hidden);
  expect_fresh("channel 2 shown again", 1);
  s.preintegration = false;
  expect_fresh("pre-integration off", 0, false);
  EXPECT_TRUE(reused.preint_tables.empty());
}

}  // namespace
}  // namespace resoct
