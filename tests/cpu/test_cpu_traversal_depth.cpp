// The residency traversal's descent (kernel/residency_descent.glsl.h): restarting below the deepest
// node shared with the previous descent, and capping the depth at the sampled level's "leaves",
// must never change which visible samples run. Checked against descent-free renders (start_depth at
// the traversal depth: every node classified from its own record only) and against page-table
// mode, over seeded random cameras.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "resoct/scene/camera.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

Camera random_camera(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  std::uniform_real_distribution<double> height(-0.9, 0.9);
  std::uniform_real_distribution<double> dist(1.2, 2.5);
  std::uniform_real_distribution<double> jitter(0.35, 0.65);
  const double a = angle(rng), h = height(rng), r = dist(rng);
  Camera c;
  c.eye = {0.5 + r * std::cos(a) * std::sqrt(1.0 - h * h), 0.5 + r * h,
           0.5 + r * std::sin(a) * std::sqrt(1.0 - h * h)};
  c.target = {jitter(rng), jitter(rng), jitter(rng)};
  c.fov_deg = 40.0;
  return c;
}

// Three channels of sparse tubes, visible above rising thresholds: a descent drops the channels
// one by one at different depths, so restarts must carry the per-depth channel state exactly.
Scene three_channel_scene(const Camera& cam) {
  Scene s = make_scene(40, cam);
  s.step_scale = 0.5;
  s.lod_error_px = 1e-3;  // level 0 everywhere: the depth cap never applies
  const double lo[3] = {0.1, 0.3, 0.5};
  for (std::uint32_t c = 0; c < 3; ++c) {
    s.channels.push_back(make_channel(c,
                                      {{0.0, {1, 1, 1, 0}},
                                       {lo[c], {1, 1, 1, 0}},
                                       {lo[c] + 0.05, {c == 0 ? 1.0 : 0.3, 0.6, 0.2, 0.2}},
                                       {1.0, {0.2, c == 1 ? 1.0 : 0.3, 0.9, 0.5}}},
                                      0, 0));
  }
  return s;
}

// With complete metadata a channel empty at a node is empty at every descendant (records are
// unions of their children's), so the channels skipped at the traversal node do not depend on
// where the descent starts, nor on which of its depths were reused from the previous node's
// descent: samples, brick reads and the image equal those of a render that classifies the
// traversal node alone (start_depth = leaf depth, no descent at all).
TEST(CpuTraversalDepth, IncrementalDescentMatchesNodeOwnClassification) {
  ProceduralSource src("procedural:tubes:64x64x64:3", bricks8());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);  // five depths
  ResidentScene rs(src, {0, 1, 2}, ro);
  const std::uint32_t leaf = rs.layout().leaf_depth();
  ASSERT_GE(leaf, 4u);
  std::mt19937 rng(20261121u);
  std::uint64_t total_samples = 0;
  for (int view = 0; view < 6; ++view) {
    const Scene s = three_channel_scene(random_camera(rng));
    FrameOptions o;
    o.mode = RenderMode::residency;
    // Visible subtrees only where nothing below is hidden (skip_min_samples 0), so that every
    // empty leaf the flat render skips, the descent skips too.
    const Rendered descent = render_cpu(rs, s, o, 0.0f);
    o.start_depth = leaf;
    const Rendered flat = render_cpu(rs, s, o, 0.0f);
    o.mode = RenderMode::pagetable;
    o.start_depth = 0;
    const Rendered pt = render_cpu(rs, s, o);
    EXPECT_EQ(descent.stats.samples, flat.stats.samples) << view;
    EXPECT_EQ(descent.stats.brick_accesses, flat.stats.brick_accesses) << view;
    // The same sample positions to the bit: step j of the grid is t_grid + j * dt however the
    // march got there (docs/rendering.md, "Skipping keeps the sample grid"), and the same
    // level-0 bricks hold the same values, so the images are identical.
    EXPECT_EQ(max_diff(descent.image, flat.image), 0.0) << view;
    EXPECT_LT(max_diff(descent.image, pt.image), 3e-4) << view;
    // Positions visited are not compared: a skip also goes on through the empty nodes that
    // follow at its depth (runs, docs/rendering.md "Segments"), so the leaf-only render skips
    // long stretches too, and which of the two needs fewer passes depends on the view.
    EXPECT_EQ(descent.stats.cap_hits, 0u);
    EXPECT_TRUE(descent.nodes.empty());
    total_samples += descent.stats.samples;
  }
  EXPECT_GT(total_samples, 0u);
}

// Steps of 1-1.7 voxels through 2³ leaves: the leaf changes on most steps, yet consecutive leaves
// share ancestors. The descent-free render classifies exactly one node per leaf entered; the
// descent enters fewer leaves (it skips empty subtrees) but also classifies ancestors. With a
// full descent per leaf change (leaf depth + 1 = 6 nodes each) that cost 1.6× the descent-free
// count on this view (31603 vs 19262 nodes); reusing the shared ancestors makes it cheaper
// (about two nodes per change: 1 + 1/2 + 1/4 + ...).
TEST(CpuTraversalDepth, IncrementalDescentVisitsFewerNodesThanFullDescents) {
  ProceduralSource src("procedural:tubes:64x64x64", bricks8());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(2);
  ResidentScene rs(src, {0}, ro);
  const std::uint32_t leaf = rs.layout().leaf_depth();
  ASSERT_GE(leaf, 5u);
  std::mt19937 rng(7u);
  Scene s = three_channel_scene(random_camera(rng));
  s.channels.resize(1);
  s.step_scale = 1.0;
  FrameOptions o;
  const Rendered r = render_cpu(rs, s, o);
  o.start_depth = leaf;  // each node change classifies exactly one node
  const Rendered flat = render_cpu(rs, s, o);
  ASSERT_GT(flat.stats.nodes_visited, 0u);
  EXPECT_LT(max_diff(r.image, flat.image), 3e-4);
  EXPECT_LT(r.stats.nodes_visited, flat.stats.nodes_visited)
      << r.stats.nodes_visited << " vs " << flat.stats.nodes_visited << " leaves entered";
}

// Deepest depth whose nodes are at least `need` voxels on every axis (brute force).
std::uint32_t depth_with_nodes_of(const OctreeLayout& layout, glm::u64vec3 need) {
  std::uint32_t best = 0;
  for (std::uint32_t d = 0; d < layout.depth_count(); ++d) {
    const glm::u64vec3 e = layout.depth(d).node_extent;
    if (e.x >= need.x && e.y >= need.y && e.z >= need.z) best = d;
  }
  return best;
}

// All channels sample level 2 or coarser and steps are about a level-0 voxel: without the cap the
// traversal would descend to the 2³ leaves. Capped, it stops at nodes of two level-2 voxels (8³,
// one trilinear footprint of the sampled level): at most cap + 1 nodes per position, and the same
// image as a render that classifies those nodes without a descent (start_depth = cap), from no
// more samples.
TEST(CpuTraversalDepth, CoarseLevelsCapTheDepth) {
  ProceduralSource src("procedural:tubes:64x64x64", bricks8());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(2);
  ResidentScene rs(src, {0}, ro);
  ASSERT_GE(src.hierarchy().level_count(), 3u);
  const std::uint32_t cap = depth_with_nodes_of(rs.layout(), glm::u64vec3(8));
  ASSERT_LT(cap + 1, rs.layout().leaf_depth());
  std::mt19937 rng(99u);
  for (int view = 0; view < 3; ++view) {
    Scene s = make_scene(32, random_camera(rng));
    s.step_scale = 0.25;
    s.channels = {make_channel(0,
                               {{0.0, {1, 1, 1, 0}},
                                {0.1, {1, 1, 1, 0}},
                                {0.2, {1, 0.8, 0.3, 0.1}},
                                {1.0, {1, 0.2, 0.1, 0.6}}},
                               2, 15)};
    FrameOptions o;
    const Rendered res = render_cpu(rs, s, o);
    o.start_depth = cap;
    const Rendered flat = render_cpu(rs, s, o);
    ASSERT_GT(res.stats.samples, 0u);
    // At level 2 a node's culling holds in the node shrunk by half a level voxel (exact culling,
    // docs/rendering.md): skipping a large empty ancestor skips every sample that skipping its
    // capped descendants would, and the rims inside it too.
    EXPECT_LE(res.stats.samples, flat.stats.samples) << view;
    EXPECT_EQ(res.stats.samples, res.stats.brick_accesses) << view;
    EXPECT_LT(max_diff(res.image, flat.image), 1e-4) << view;
    EXPECT_LE(res.stats.nodes_visited, res.stats.iterations * (cap + 1))
        << view << ": " << res.stats.nodes_visited << " nodes, " << res.stats.iterations
        << " positions";
  }
}

}  // namespace
}  // namespace resoct::test
