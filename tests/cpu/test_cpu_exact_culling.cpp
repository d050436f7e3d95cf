// Exact culling (docs/rendering.md "Exact culling"): on fully resident data an image must not
// depend on what was skipped. Every mode is checked against the dense double-precision reference
// and against the page-table mode, for transfer functions that show value 0, bands between the
// values the voxels hold, and channels that sample coarse levels.
#include <cmath>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "support/function_source.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

// Reference tolerances of the sphere scenes (step 1/4 voxel against the oracle's 1/16, a
// 1024-entry LUT against the exact transfer function): measured 8.3e-4 max and 6.8e-5 RMSE in
// every mode; the bounds are three times that. Skipping the zero bricks whatever the transfer
// function says (the defect fixed here) fails them by far: 0.44 max, RMSE 0.08.
constexpr double kRefMax = 2.5e-3;
constexpr double kRefRmse = 2e-4;

constexpr RenderMode kModes[] = {RenderMode::residency, RenderMode::pagetable, RenderMode::octree};

const char* mode_name(RenderMode m) {
  return m == RenderMode::residency   ? "residency"
         : m == RenderMode::pagetable ? "pagetable"
                                      : "octree";
}

// The sphere is 0 outside its radius: at 64³ the corner bricks (8³) and nodes are all zeros.
Scene sphere_scene(double alpha_at_zero) {
  Scene s = make_scene(40, oblique_camera());
  s.channels = {make_channel(
      0, {{0.0, {0.3, 0.5, 0.9, alpha_at_zero}}, {0.4, {1, 0.6, 0.2, 0.06}}, {1.0, {1, 1, 1, 0.3}}},
      0, 0)};
  return s;
}

// A cube of `edge` u8 voxels holding a ball of 255 (radius 21/64 of the edge, a little off the
// centre) in zeros: a "binary mask", whose values are 0 or 255 only.
VolumeDesc binary_ball_volume(std::uint32_t edge) {
  VolumeDesc v;
  v.extent = {edge, edge, edge};
  v.type = VoxelType::u8;
  return v;
}
FunctionSource::ValueFn binary_ball(std::uint32_t edge) {
  const double k = edge / 32.0;
  return [k](std::uint32_t, const glm::u64vec3& p) {
    const glm::dvec3 d = glm::dvec3(p) + 0.5 - k * glm::dvec3(16.0, 14.0, 17.0);
    return glm::dot(d, d) < (10.5 * k) * (10.5 * k) ? 255.0 : 0.0;
  };
}

void expect_reference(const Rendered& r, const Image& ref, const std::string& what) {
  EXPECT_LT(max_diff(r.image, ref), kRefMax) << what;
  EXPECT_LT(compare_images(r.image, ref).rmse_rgb, kRefRmse) << what;
  EXPECT_EQ(r.stats.cap_hits, 0u) << what;
}

// A haze at value 0 (a CT-like background): all-zero bricks are EMPTY pages and all-zero nodes
// have the range [0, 0]; both must render like the dense march, in every mode. With opacity 0 at
// value 0 they are skipped as before.
TEST(ExactCulling, OpacityAtZeroRendersInEveryMode) {
  ProceduralSource src("procedural:sphere:64x64x64", bricks8());
  ResidentScene rs(src, {0});
  for (double a0 : {0.02, 0.0}) {
    const Scene s = sphere_scene(a0);
    const Image ref = render_reference(s, src.hierarchy().volume(), level0_voxels(src));
    for (RenderMode m : kModes) {
      FrameOptions o;
      o.mode = m;
      const Rendered r = render_cpu(rs, s, o);
      expect_reference(r, ref, std::string(mode_name(m)) + " alpha(0) = " + std::to_string(a0));
    }
  }
}

// A "binary mask": voxels are 0 or 255 only, so node occupancy holds two bins, yet trilinear
// samples between a 0 and a 255 voxel take every value in between. A transfer function visible
// only in a band in the middle shows the mask's boundary surface: no node may be culled because
// its voxels' bins miss the band (the occupancy test did exactly that).
TEST(ExactCulling, BandsBetweenOccupiedValuesAreNotCulled) {
  const VolumeDesc v = binary_ball_volume(32);
  FunctionSource src(v, bricks8(), binary_ball(32));
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);
  ResidentScene rs(src, {0}, ro);
  Scene s = make_scene(40, oblique_camera());
  // The value crosses the band within a fraction of a voxel: march at the oracle's step, so that
  // what remains is the LUT's error, not the midpoint rule's.
  s.step_scale = 1.0 / 16.0;
  s.channels = {make_channel(
      0, {{0.0, {1, 1, 1, 0}}, {0.3, {1, 1, 1, 0}}, {0.5, {1, 0.7, 0.2, 0.3}}, {0.7, {1, 1, 1, 0}}},
      0, 0)};
  const Image ref = render_reference(
      s, v, [&](std::uint32_t c, const glm::i64vec3& p) { return src.voxel(0, c, p); });
  // The band is steep (the value crosses it within a tenth of a voxel), so the 1024-entry LUT
  // errs by up to 5.4e-3 here (measured, the same in every mode, RMSE 4e-4); a node culled
  // by occupancy would lose the whole surface (differences of 0.2 and more).
  FrameOptions o;
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  EXPECT_LT(max_diff(pt.image, ref), 1e-2);
  EXPECT_LT(compare_images(pt.image, ref).rmse_rgb, 1e-3);
  for (RenderMode m : {RenderMode::residency, RenderMode::octree}) {
    o.mode = m;
    const Rendered r = render_cpu(rs, s, o);
    // Skips advance t by k·dt in one addition (measured 7e-5 apart from the page table's march).
    EXPECT_LT(max_diff(r.image, pt.image), 2e-4) << mode_name(m);
    EXPECT_GT(r.stats.samples, 0u);
  }
}

// Channels that sample coarse levels only: culled nodes must not take away the visible
// neighbours of samples near their faces (a level-l sample reads voxels up to half a level voxel
// beyond the node). Residency, standard octree and page table agree within 1/255 at every pixel
// for levels [2, 2] and [3, 3], with 4³ leaves (fine nodes, so many faces).
TEST(ExactCulling, CoarseLevelsCullOnlyWhatTheirSamplesCannotSee) {
  ProceduralSource src("procedural:tubes:128x128x128", bricks8());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);
  ResidentScene rs(src, {0}, ro);
  for (std::uint32_t level : {2u, 3u}) {
    Scene s = make_scene(64, oblique_camera());
    s.step_scale = 0.5;
    s.channels = {make_channel(0,
                               {{0.0, {1, 1, 1, 0}},
                                {0.15, {1, 1, 1, 0}},
                                {0.25, {1, 0.8, 0.3, 0.2}},
                                {1.0, {1, 0.2, 0.1, 0.7}}},
                               level, level)};
    FrameOptions o;
    const Rendered res = render_cpu(rs, s, o);
    o.mode = RenderMode::pagetable;
    const Rendered pt = render_cpu(rs, s, o);
    EXPECT_LT(max_diff(res.image, pt.image), 1.0 / 255.0) << "level " << level;
    EXPECT_GT(res.stats.distance_skipped, 0.0) << "level " << level << ": nothing culled";
    // The standard-octree mode culls whole bricks of the walk by the same node records (the
    // node that is the brick, shrunk by the walked level's margin).
    o.mode = RenderMode::octree;
    const Rendered oct = render_cpu(rs, s, o);
    EXPECT_LT(max_diff(oct.image, pt.image), 1.0 / 255.0) << "octree, level " << level;
  }
}

// The standard-octree mode (paper 000 §8's baseline) culls with the residency mode's data: a
// brick of its walk whose node record the transfer function cannot see ends the walk with the
// channel empty, so on sparse blobs over a hidden noise floor it takes far fewer samples than the
// page table (which skips only all-zero bricks) and renders the same image.
TEST(ExactCulling, StandardOctreeCullsBricksByTheirNodeRecords) {
  ProceduralSource src("procedural:noisefloor:64x64x64", bricks8());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);
  ResidentScene rs(src, {0}, ro);
  Scene s = make_scene(40, oblique_camera());
  s.channels = {make_channel(
      0,
      {{0.0, {1, 1, 1, 0}}, {0.2, {1, 1, 1, 0}}, {0.4, {1, 0.6, 0.2, 0.1}}, {1.0, {1, 1, 1, 0.4}}},
      0, 0)};
  FrameOptions o;
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  o.mode = RenderMode::octree;
  const Rendered oct = render_cpu(rs, s, o);
  ASSERT_GT(pt.stats.samples, 0u);
  EXPECT_LT(double(oct.stats.samples), 0.7 * double(pt.stats.samples));
  EXPECT_GT(oct.stats.distance_skipped, pt.stats.distance_skipped);
  // Skips advance t by k·dt in one addition, as in the residency mode.
  EXPECT_LT(max_diff(oct.image, pt.image), 2e-4);
  EXPECT_TRUE(oct.nodes.empty()) << "every record is supplied: nothing to request";
}

// A node whose value range the transfer function shows wholly (every value of its range visible)
// can have no EMPTY node below it: the residency march stops its descent there and takes the
// node's whole box as one visible node (kernel resoct_node_full). Nothing is skipped either way,
// so the image is the page table's to the bit; what changes is the node visits, one per ray
// (the root) instead of a descent per 4³ leaf. The same data under a transfer function that hides
// its lower half descends as before.
TEST(ExactCulling, WhollyVisibleNodesEndTheDescentWithoutChangingTheImage) {
  VolumeDesc v;
  v.extent = {32, 32, 32};
  v.type = VoxelType::u8;
  FunctionSource src(v, bricks8(), [](std::uint32_t, const glm::u64vec3& p) {
    const glm::dvec3 q(p);
    return std::round(150.0 + 90.0 * std::sin(0.3 * q.x) * std::cos(0.25 * q.y) *
                                  std::sin(0.2 * q.z + 1.0));
  });
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);
  ResidentScene rs(src, {0}, ro);
  for (double hidden_below : {0.1, 0.5}) {
    Scene s = make_scene(40, oblique_camera());
    s.channels = {make_channel(0,
                               {{0.0, {1, 1, 1, 0}},
                                {hidden_below, {1, 1, 1, 0}},
                                {hidden_below + 0.05, {0.9, 0.6, 0.2, 0.05}},
                                {1.0, {1, 1, 1, 0.2}}},
                               0, 0)};
    const std::string what = "hidden below " + std::to_string(hidden_below);
    FrameOptions o;
    o.mode = RenderMode::pagetable;
    const Rendered pt = render_cpu(rs, s, o);
    o.mode = RenderMode::residency;
    // Visible subtrees only where nothing below is hidden (skip_min_samples 0): the descent into
    // the hidden half is what this test watches.
    const Rendered res = render_cpu(rs, s, o, 0.0f);
    ASSERT_GT(res.stats.samples, 0u) << what;
    if (hidden_below < 0.2) {
      // Values 60..240 (0.24..0.94): all visible, nothing to skip.
      EXPECT_EQ(max_diff(res.image, pt.image), 0.0) << what;
      EXPECT_EQ(res.stats.samples, pt.stats.samples) << what;
      EXPECT_LE(res.stats.nodes_visited, res.stats.rays) << what;
    } else {
      EXPECT_LT(max_diff(res.image, pt.image), 2e-4) << what;
      EXPECT_GT(res.stats.nodes_visited, 2 * res.stats.rays) << what;
    }
  }
}

// A visible node that contains every live channel's target brick computes no exit: its exit is
// never before the sources' (docs/rendering.md "Nodes that hold the sources"). Nodes smaller than
// the bricks must still end segments. A 64³ volume of 16³ bricks holds, in each brick, a slab of
// 200 at x in [0, 4) and zeros elsewhere; the view looks down the x axis. With 4³ leaves, the
// leaf at x in [8, 12) of each brick is EMPTY (its records cover one voxel around it, all zeros)
// and follows a visible leaf inside the same brick: residency mode ends the visible leaf's segment
// and skips the EMPTY one, so it takes 0.67 of the samples of the page table, which samples whole
// bricks (measured). Treating every visible node as holding the bricks leaves the image alone but
// takes 0.84 of them (measured): it skips only EMPTY leaves in which a brick's segment begins. With
// 16³ and 32³ leaves every node holds the bricks and none is EMPTY: the page table's samples.
TEST(ExactCulling, OnlyNodesThatHoldTheBricksEndNoSegment) {
  VolumeDesc v;
  v.extent = {64, 64, 64};
  v.type = VoxelType::u8;
  BrickLayout bricks;
  bricks.brick_size = glm::uvec3(16);
  bricks.halo = 1;
  FunctionSource src(
      v, bricks, [](std::uint32_t, const glm::u64vec3& p) { return p.x % 16u < 4u ? 200.0 : 0.0; });
  Scene s = make_scene(64);
  s.channels = {make_channel(0,
                             {{0.0, {1, 1, 1, 0}},
                              {0.3, {1, 1, 1, 0}},
                              {0.5, {1, 0.6, 0.2, 0.02}},
                              {1.0, {1, 1, 1, 0.05}}},
                             0, 0)};
  FrameOptions o;
  for (std::uint32_t leaf : {4u, 16u, 32u}) {
    ResidentOptions ro;
    ro.leaf_size = glm::uvec3(leaf);
    ResidentScene rs(src, {0}, ro);
    const std::string what = "leaf " + std::to_string(leaf);
    o.mode = RenderMode::pagetable;
    const Rendered pt = render_cpu(rs, s, o);
    o.mode = RenderMode::residency;
    const Rendered res = render_cpu(rs, s, o);
    ASSERT_GT(res.stats.samples, 0u) << what;
    EXPECT_LT(max_diff(res.image, pt.image), 2e-4) << what;
    if (leaf == 4u) {
      EXPECT_LT(double(res.stats.samples), 0.75 * double(pt.stats.samples)) << what;
    } else {
      EXPECT_EQ(res.stats.samples, pt.stats.samples) << what;
    }
  }
}

// A 32³ voxel checkerboard of 10 and 240, in which every node's range straddles the [0, 0.1]
// that hides_below_a_tenth() hides; octree leaves of 4³.
VolumeDesc checkerboard_volume() {
  VolumeDesc v;
  v.extent = {32, 32, 32};
  v.type = VoxelType::u8;
  return v;
}
double checkerboard(const glm::u64vec3& p) {
  return (p.x + p.y + p.z) % 2 == 0 ? 240.0 : 10.0;
}
Scene hides_below_a_tenth() {
  Scene s = make_scene(40, oblique_camera());
  s.channels = {make_channel(0,
                             {{0.0, {1, 1, 1, 0}},
                              {0.1, {1, 1, 1, 0}},
                              {0.15, {0.9, 0.6, 0.2, 0.05}},
                              {1.0, {1, 1, 1, 0.2}}},
                             0, 0)};
  return s;
}
ResidentOptions leaves4() {
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(4);
  return ro;
}

// A voxel checkerboard of 10 and 240 under a transfer function that hides [0, 0.1]: every node's
// range [10, 240] holds hidden values, so no record proves its node wholly visible
// (resoct_node_full), yet no node is EMPTY. The frame's visible-subtree bits (built on the host
// from every node below, render/visible_subtrees.hpp) end the descent at the root: one node per
// ray instead of a descent per 4³ leaf, the page table's samples and image to the bit. Without
// the bits the same tables descend to the leaves.
TEST(ExactCulling, VisibleSubtreesEndTheDescentWhereEveryNodeStraddlesHiddenValues) {
  FunctionSource src(checkerboard_volume(), bricks8(),
                     [](std::uint32_t, const glm::u64vec3& p) { return checkerboard(p); });
  ResidentScene rs(src, {0}, leaves4());
  const Scene s = hides_below_a_tenth();
  FrameOptions o;
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  o.mode = RenderMode::residency;
  FrameTables with = rs.tables(s, o);
  ASSERT_FALSE(with.visible_subtrees.empty());
  EXPECT_EQ(with.visible_subtrees[0], 1u) << "the root's subtree is visible for entry 0";
  FrameTables without = with;
  without.visible_subtrees.clear();
  cpu::CpuBackend backend(1);
  rs.upload(backend);
  FrameResult a;
  backend.render(with, a);
  FrameResult b;
  backend.render(without, b);
  ASSERT_GT(pt.stats.samples, 0u);
  EXPECT_EQ(a.stats.samples, pt.stats.samples);
  EXPECT_EQ(max_diff(a.image, pt.image), 0.0);
  EXPECT_LE(a.stats.nodes_visited, a.stats.rays);
  EXPECT_EQ(b.stats.samples, pt.stats.samples);
  EXPECT_GT(b.stats.nodes_visited, 2 * b.stats.rays);
  EXPECT_EQ(max_diff(b.image, pt.image), 0.0);
}

// TuningOptions::skip_min_samples widens the visible-subtree bits over nodes that hide too little
// for their descent to pay: the checkerboard of the test above with pockets of hidden noise
// (12³ cells of values 1-3, under the hidden 0.1, not homogeneous), whose inner 4³ leaves are
// EMPTY (their records reach one voxel past them). The leaves are smaller than the 8³ bricks, so
// widening over them requests no brick. With an allowance of 0 the pockets' ancestors lose their
// bits and rays descend to skip them; with larger ones the nodes above keep them and the pockets
// are sampled, transparent. The image is the page table's, to the bit,
// for every allowance; only the nodes visited and the samples taken change.
TEST(ExactCulling, WideningTheVisibleSubtreesChangesWorkNotTheImage) {
  FunctionSource src(checkerboard_volume(), bricks8(), [](std::uint32_t, const glm::u64vec3& p) {
    const glm::u64vec3 cell = p / std::uint64_t(12);
    if (cell.x + cell.y + cell.z == 3) return double(1 + (p.x + p.y + p.z) % 3);
    return checkerboard(p);
  });
  ResidentScene rs(src, {0}, leaves4());
  const Scene s = hides_below_a_tenth();
  FrameOptions o;
  o.mode = RenderMode::pagetable;
  const Rendered pt = render_cpu(rs, s, o);
  o.mode = RenderMode::residency;
  cpu::CpuBackend backend(1);
  rs.upload(backend);
  std::vector<FrameResult> results;
  for (float k : {0.0f, kDefaultSkipMinSamples, 1e6f}) {
    results.emplace_back();
    backend.render(rs.tables(s, o, k), results.back());
    const FrameResult& r = results.back();
    EXPECT_EQ(max_diff(r.image, pt.image), 0.0) << "skip_min_samples " << k;
    EXPECT_EQ(r.stats.cap_hits, 0u) << "skip_min_samples " << k;
  }
  ASSERT_GT(pt.stats.samples, 0u);
  EXPECT_LT(results[0].stats.samples, pt.stats.samples) << "0: every pocket is skipped";
  EXPECT_GT(results[0].stats.nodes_visited, results[2].stats.nodes_visited);
  EXPECT_LE(results[2].stats.nodes_visited, results[2].stats.rays) << "one node per ray";
  EXPECT_EQ(results[2].stats.samples, pt.stats.samples) << "every pocket is sampled";
  EXPECT_LE(results[1].stats.nodes_visited, results[0].stats.nodes_visited);
  EXPECT_GE(results[1].stats.nodes_visited, results[2].stats.nodes_visited);
}

// Where a channel samples a coarse level, a node's class holds only inside the node shrunk by
// half a voxel of that level (the trilinear support reaches that far beyond it); in the rim that
// is left, every channel is looked up. An all-zero brick there is an EMPTY page, which settles
// the channel as in the page-table mode: the residency march skips it (it used to step through
// its samples, which add nothing). Values are 0 or 255, the transfer function hides [0, 0.1] and
// the leaves are the sampled level's bricks, so no node is empty where its brick is not: the
// residency mode skips exactly the page table's distance and renders its image.
TEST(ExactCulling, EmptyBricksInTheRimOfEmptyNodesAreSkipped) {
  FunctionSource src(binary_ball_volume(64), bricks8(), binary_ball(64));
  for (std::uint32_t level : {0u, 1u}) {
    ResidentOptions ro;
    ro.leaf_size = glm::uvec3(8u << level);
    ResidentScene rs(src, {0}, ro);
    Scene s = make_scene(40, oblique_camera());
    s.channels = {make_channel(0,
                               {{0.0, {1, 1, 1, 0}},
                                {0.1, {1, 1, 1, 0}},
                                {0.4, {1, 0.6, 0.2, 0.06}},
                                {1.0, {1, 1, 1, 0.3}}},
                               level, level)};
    const std::string what = "level " + std::to_string(level);
    FrameOptions o;
    o.mode = RenderMode::pagetable;
    const Rendered pt = render_cpu(rs, s, o);
    o.mode = RenderMode::residency;
    const Rendered res = render_cpu(rs, s, o);
    ASSERT_GT(pt.stats.distance_skipped, 0.0) << what;
    // Level 1 without the brick skip: 165.1 of the page table's 245.3 box units.
    EXPECT_NEAR(res.stats.distance_skipped, pt.stats.distance_skipped,
                1e-6 * pt.stats.distance_skipped)
        << what;
    EXPECT_EQ(res.stats.samples, pt.stats.samples) << what;
    EXPECT_LT(max_diff(res.image, pt.image), 2e-4) << what;
  }
}

}  // namespace
}  // namespace resoct::test
