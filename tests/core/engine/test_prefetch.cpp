// Camera extrapolation and the conservative view-brick enumeration used for prefetching.
#include <gtest/gtest.h>

#include <set>

#include "resoct/base/error.hpp"
#include "resoct/engine/prefetch.hpp"

namespace resoct {
namespace {

Scene scene_for(const Camera& cam, std::uint32_t channels = 1) {
  Scene s;
  s.camera = cam;
  s.viewport = {64, 64};
  for (std::uint32_t c = 0; c < channels; ++c) {
    ChannelSettings ch;
    ch.channel = c;
    s.channels.push_back(ch);
  }
  return s;
}

BrickHierarchy hierarchy(glm::u64vec3 extent = {256, 256, 256}, std::uint32_t channels = 1) {
  VolumeDesc v;
  v.extent = extent;
  v.channels = channels;
  return BrickHierarchy(v, BrickLayout{glm::uvec3(16), 1});
}

TEST(CameraPredictor, ExtrapolatesLinearlyFromTheLastTwoPoses) {
  CameraPredictor p;
  Camera a;
  EXPECT_TRUE(p.predict(3).empty());
  p.observe(a);
  EXPECT_TRUE(p.predict(3).empty());
  Camera b = a;
  b.eye += glm::dvec3(0.1, 0.0, -0.05);
  b.target += glm::dvec3(0.0, 0.02, 0.0);
  p.observe(b);
  const auto poses = p.predict(3);
  ASSERT_EQ(poses.size(), 3u);
  for (int k = 1; k <= 3; ++k) {
    const Camera& c = poses[std::size_t(k - 1)];
    EXPECT_NEAR(c.eye.x, a.eye.x + 0.1 * (k + 1), 1e-12);
    EXPECT_NEAR(c.eye.z, a.eye.z - 0.05 * (k + 1), 1e-12);
    EXPECT_NEAR(c.target.y, a.target.y + 0.02 * (k + 1), 1e-12);
    EXPECT_EQ(c.up, a.up);
    EXPECT_EQ(c.fov_deg, a.fov_deg);
  }
  p.observe(b);  // at rest
  EXPECT_TRUE(p.predict(3).empty());
  p.reset();
  EXPECT_TRUE(p.predict(1).empty());
}

TEST(ViewBricks, LooksAwayFromTheVolumeGivesNothing) {
  const BrickHierarchy h = hierarchy();
  Camera cam;
  cam.eye = {2.0, 0.5, 0.5};
  cam.target = {3.0, 0.5, 0.5};  // facing +x, the volume is behind
  EXPECT_TRUE(view_bricks(h, scene_for(cam), 1000).empty());
  cam.target = {2.0, 0.5, 1.5};  // facing +z: the volume lies 63°+ to the side, fov is 40°
  EXPECT_TRUE(view_bricks(h, scene_for(cam), 1000).empty());
}

TEST(ViewBricks, CoarseFirstWithinBudgetAndFilter) {
  const BrickHierarchy h = hierarchy({256, 256, 256}, 2);
  Camera cam;
  cam.eye = {1.6, 0.5, 0.5};
  const Scene s = scene_for(cam, 2);
  const auto all = view_bricks(h, s, 1u << 20);
  ASSERT_FALSE(all.empty());
  std::set<BrickKey> unique(all.begin(), all.end());
  EXPECT_EQ(unique.size(), all.size());
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_GE(all[i - 1].level(), all[i].level());
  // Both channels, each brick for both (they share the level range).
  std::size_t per_channel[2] = {0, 0};
  for (const BrickKey k : all) ++per_channel[k.channel()];
  EXPECT_EQ(per_channel[0], per_channel[1]);
  EXPECT_GT(per_channel[0], 0u);
  // Budget and filter: the first keys of the unfiltered list that pass.
  const auto even = [](BrickKey k) { return k.channel() == 0; };
  const auto some = view_bricks(h, s, 5, even);
  ASSERT_EQ(some.size(), 5u);
  std::vector<BrickKey> expected;
  for (const BrickKey k : all) {
    if (k.channel() == 0 && expected.size() < 5) expected.push_back(k);
  }
  EXPECT_EQ(some, expected);
}

TEST(ViewBricks, ContainsEveryBrickSampledAtTheLodOfItsDepth) {
  // Brute force: sample the frustum densely along pixel rays, compute the LOD of each sample's
  // depth by the rule of docs/rendering.md, and require that brick in the enumeration.
  const BrickHierarchy h = hierarchy({128, 128, 64});
  Camera cam;
  cam.eye = {0.9, 0.7, 1.3};
  cam.target = {0.4, 0.3, 0.2};
  Scene s = scene_for(cam);
  s.viewport = {24, 20};
  s.lod_error_px = 2.0;
  const auto listed = view_bricks(h, s, 1u << 22);
  const std::set<BrickKey> set(listed.begin(), listed.end());
  const CameraRays rays(s.camera, s.viewport);
  const glm::dvec3 box = box_extent(h.volume());
  std::size_t checked = 0;
  for (std::uint32_t py = 0; py < s.viewport.height; ++py) {
    for (std::uint32_t px = 0; px < s.viewport.width; ++px) {
      const Ray r = rays.pixel_ray(px, py);
      for (double t = 0.0; t < 3.0; t += 0.01) {
        const glm::dvec3 p = r.origin + t * r.dir;
        if (glm::any(glm::lessThan(p, glm::dvec3(0.0))) || glm::any(glm::greaterThan(p, box))) {
          continue;
        }
        const double budget = s.lod_error_px * rays.footprint(rays.depth(p));
        std::uint32_t l = 0;
        while (l + 1 < h.level_count()) {
          const glm::dvec3 vs = level_voxel_size(h, l + 1);
          if (std::max({vs.x, vs.y, vs.z}) > budget) break;
          ++l;
        }
        const BrickKey key(l, 0, h.brick_at(l, box_to_normalized(h.volume(), p)));
        ASSERT_TRUE(set.count(key)) << "pixel " << px << "," << py << " t " << t << " level " << l;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000u);
  // Conservative, not everything: fewer than all bricks of all levels.
  EXPECT_LT(listed.size(), h.bricks_per_channel());
}

}  // namespace
}  // namespace resoct
