// Camera rays and pixel footprints against hand-computed geometry; box/normalized conversion.
#include <cmath>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "resoct/scene/camera.hpp"
#include "support/expect_error.hpp"

namespace {

using namespace resoct;

void expect_vec_near(const glm::dvec3& a, const glm::dvec3& b, double eps) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

TEST(Camera, PerspectiveRaysThroughPixelCentres) {
  Camera cam;
  cam.eye = {0.5, 0.5, 3.0};
  cam.target = {0.5, 0.5, 0.5};
  cam.up = {0.0, 1.0, 0.0};
  cam.fov_deg = 90.0;
  const CameraRays rays(cam, Viewport{4, 2});
  // Looking along -z; right is +x, up is +y. Image plane at depth 1 spans y in [-1, 1] (fov 90)
  // and x in [-2, 2] (aspect 2). Pixel (0, 0) centre: x = -2 + 0.5 * 4/4 = -1.5, y = 0.5.
  const Ray r = rays.pixel_ray(0, 0);
  expect_vec_near(r.origin, cam.eye, 0.0);
  expect_vec_near(r.dir, glm::normalize(glm::dvec3(-1.5, 0.5, -1.0)), 1e-12);
  const Ray r2 = rays.pixel_ray(3, 1);
  expect_vec_near(r2.dir, glm::normalize(glm::dvec3(1.5, -0.5, -1.0)), 1e-12);
  // The image centre looks at the target.
  expect_vec_near(rays.ray(2.0, 1.0).dir, glm::dvec3(0, 0, -1), 1e-12);
  expect_vec_near(rays.forward(), glm::dvec3(0, 0, -1), 1e-12);
  expect_vec_near(rays.right(), glm::dvec3(1, 0, 0), 1e-12);
  expect_vec_near(rays.up(), glm::dvec3(0, 1, 0), 1e-12);
}

TEST(Camera, PerspectiveFootprintIsAnglePerPixelTimesDepth) {
  Camera cam;
  cam.fov_deg = 40.0;
  const CameraRays rays(cam, Viewport{640, 480});
  const double slope = 2.0 * std::tan(glm::radians(20.0)) / 480.0;
  EXPECT_DOUBLE_EQ(rays.footprint_base(), 0.0);
  EXPECT_NEAR(rays.footprint_slope(), slope, 1e-15);
  EXPECT_NEAR(rays.footprint(2.5), 2.5 * slope, 1e-15);
  // Brute force: neighbouring pixel rays at depth z are one footprint apart (image centre).
  const double z = 1.7;
  const Ray a = rays.ray(320.0, 240.0);
  const Ray b = rays.ray(321.0, 240.0);
  const glm::dvec3 pa = a.origin + a.dir * (z / glm::dot(a.dir, rays.forward()));
  const glm::dvec3 pb = b.origin + b.dir * (z / glm::dot(b.dir, rays.forward()));
  EXPECT_NEAR(glm::length(pb - pa), rays.footprint(z), 1e-12);
  EXPECT_NEAR(rays.depth(pa), z, 1e-12);
}

TEST(Camera, OrthographicRaysAreParallel) {
  Camera cam;
  cam.eye = {0.5, 0.5, 2.0};
  cam.target = {0.5, 0.5, 0.0};
  cam.projection = Projection::orthographic;
  cam.ortho_height = 1.0;
  const CameraRays rays(cam, Viewport{8, 4});
  // View 1 tall, 2 wide; pixel (0, 0) centre at x = 0.5 - 1 + 0.125, y = 0.5 + 0.5 - 0.125.
  const Ray r = rays.pixel_ray(0, 0);
  expect_vec_near(r.dir, glm::dvec3(0, 0, -1), 1e-15);
  expect_vec_near(r.origin, glm::dvec3(-0.375, 0.875, 2.0), 1e-12);
  EXPECT_DOUBLE_EQ(rays.footprint_base(), 0.25);
  EXPECT_DOUBLE_EQ(rays.footprint_slope(), 0.0);
  EXPECT_DOUBLE_EQ(rays.footprint(100.0), 0.25);
  const Ray s = rays.pixel_ray(1, 0);
  EXPECT_NEAR(glm::length(s.origin - r.origin), 0.25, 1e-12);
}

TEST(Camera, RejectsDegenerateCameras) {
  Camera cam;
  cam.target = cam.eye;
  EXPECT_RESOCT_ERROR(CameraRays(cam, Viewport{}), ErrorCode::invalid_argument, "camera.target");
  cam = Camera{};
  cam.up = cam.target - cam.eye;
  EXPECT_RESOCT_ERROR(CameraRays(cam, Viewport{}), ErrorCode::invalid_argument, "parallel");
  cam = Camera{};
  cam.fov_deg = 180.0;
  EXPECT_RESOCT_ERROR(CameraRays(cam, Viewport{}), ErrorCode::invalid_argument, "fov_deg");
  cam = Camera{};
  cam.projection = Projection::orthographic;
  cam.ortho_height = 0.0;
  EXPECT_RESOCT_ERROR(CameraRays(cam, Viewport{}), ErrorCode::invalid_argument, "ortho_height");
  EXPECT_RESOCT_ERROR(CameraRays(Camera{}, Viewport{0, 5}), ErrorCode::invalid_argument,
                      "viewport");
  cam = Camera{};
  cam.eye.x = std::nan("");
  EXPECT_RESOCT_ERROR(CameraRays(cam, Viewport{}), ErrorCode::invalid_argument, "camera.eye");
}

TEST(Camera, BoxAndNormalizedCoordinates) {
  VolumeDesc v;
  v.extent = {200, 100, 40};
  v.spacing = {1.0, 1.0, 2.5};  // physical 200 x 100 x 100
  const glm::dvec3 box = box_extent(v);
  expect_vec_near(box, glm::dvec3(1.0, 0.5, 0.5), 1e-15);
  expect_vec_near(box_voxel_size(v), glm::dvec3(1.0 / 200, 1.0 / 200, 2.5 / 200), 1e-15);
  const glm::dvec3 p(0.25, 0.5, 1.0);
  expect_vec_near(normalized_to_box(v, p), glm::dvec3(0.25, 0.25, 0.5), 1e-15);
  expect_vec_near(box_to_normalized(v, normalized_to_box(v, p)), p, 1e-15);
}

TEST(Camera, LevelVoxelSizesFollowTheHierarchy) {
  // 1024 x 1024 x 40 with spacing 1:1:20 (32^3 bricks): the hierarchy halves x and y first
  // (docs/hierarchy.md), so the largest voxel dimension stays the z spacing for a while.
  VolumeDesc v;
  v.extent = {1024, 1024, 40};
  v.spacing = {1.0, 1.0, 20.0};
  const BrickHierarchy hier(v, BrickLayout{});
  const glm::dvec3 h = box_voxel_size(v);  // physical 1024 x 1024 x 800: h = (1, 1, 20) / 1024
  expect_vec_near(h, glm::dvec3(1.0, 1.0, 20.0) / 1024.0, 1e-15);
  const std::vector<float> table = level_size_log2_table(hier);
  ASSERT_EQ(table.size(), hier.level_count());
  for (std::uint32_t l = 0; l < hier.level_count(); ++l) {
    const glm::uvec3 f = hier.level(l).factor_log2;
    // Brute force from the definition: level voxel = 2^f level-0 voxels per axis.
    const glm::dvec3 size =
        glm::dvec3(std::pow(2.0, f.x), std::pow(2.0, f.y), std::pow(2.0, f.z)) * h;
    expect_vec_near(level_voxel_size(hier, l), size, 1e-15);
    EXPECT_NEAR(table[l], std::log2(std::max(size.x, std::max(size.y, size.z))), 1e-6);
    if (l > 0) {
      EXPECT_GE(table[l], table[l - 1]);
    }
  }
  EXPECT_NEAR(table[0], std::log2(20.0 / 1024.0), 1e-6);
  EXPECT_DOUBLE_EQ(reference_step_length(v), 1.0 / 1024.0);
}

}  // namespace
