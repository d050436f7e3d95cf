#include "resoct/scene/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "resoct/base/error.hpp"

namespace resoct {
namespace {

bool finite3(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

const char* to_string(Projection p) noexcept {
  return p == Projection::orthographic ? "orthographic" : "perspective";
}

glm::dvec3 box_extent(const VolumeDesc& volume) {
  const glm::dvec3 size = physical_size(volume);
  const double longest = std::max(size.x, std::max(size.y, size.z));
  return size / longest;
}

glm::dvec3 box_to_normalized(const VolumeDesc& volume, const glm::dvec3& box_pos) {
  return box_pos / box_extent(volume);
}

glm::dvec3 normalized_to_box(const VolumeDesc& volume, const glm::dvec3& normalized) {
  return normalized * box_extent(volume);
}

glm::dvec3 box_voxel_size(const VolumeDesc& volume) {
  return box_extent(volume) / glm::dvec3(volume.extent);
}

glm::dvec3 level_voxel_size(const BrickHierarchy& hierarchy, std::uint32_t l) {
  const glm::uvec3 f = hierarchy.level(l).factor_log2;
  const glm::dvec3 h = box_voxel_size(hierarchy.volume());
  return {std::ldexp(h.x, int(f.x)), std::ldexp(h.y, int(f.y)), std::ldexp(h.z, int(f.z))};
}

std::vector<float> level_size_log2_table(const BrickHierarchy& hierarchy) {
  std::vector<float> out;
  out.reserve(hierarchy.level_count());
  for (std::uint32_t l = 0; l < hierarchy.level_count(); ++l) {
    const glm::dvec3 s = level_voxel_size(hierarchy, l);
    out.push_back(float(std::log2(std::max(s.x, std::max(s.y, s.z)))));
  }
  return out;
}

double reference_step_length(const VolumeDesc& volume) {
  const glm::dvec3 h = box_voxel_size(volume);
  return std::min(h.x, std::min(h.y, h.z));
}

CameraRays::CameraRays(const Camera& camera, const Viewport& viewport)
    : camera_(camera), viewport_(viewport) {
  if (!finite3(camera.eye)) throw invalid_parameter("camera.eye", "must be finite");
  if (!finite3(camera.target)) throw invalid_parameter("camera.target", "must be finite");
  if (!finite3(camera.up)) throw invalid_parameter("camera.up", "must be finite");
  if (viewport.width < 1 || viewport.width > 16384 || viewport.height < 1 ||
      viewport.height > 16384) {
    throw invalid_parameter("viewport", "width and height must be in 1..16384");
  }
  const glm::dvec3 view = camera.target - camera.eye;
  const double view_len = glm::length(view);
  if (!(view_len > 0.0) || !std::isfinite(view_len)) {
    throw invalid_parameter("camera.target", "must differ from camera.eye");
  }
  forward_ = view / view_len;
  const double up_len = glm::length(camera.up);
  if (!(up_len > 0.0)) throw invalid_parameter("camera.up", "must not be zero");
  const glm::dvec3 side = glm::cross(forward_, camera.up / up_len);
  const double side_len = glm::length(side);
  // Nearly parallel vectors give a badly conditioned basis; 1e-6 rad is far below any usable view.
  if (!(side_len > 1e-6)) {
    throw invalid_parameter("camera.up", "must not be parallel to the view direction");
  }
  right_ = side / side_len;
  up_ = glm::cross(right_, forward_);

  const double rows = double(viewport.height);
  if (camera.projection == Projection::perspective) {
    if (!(camera.fov_deg > 0.0 && camera.fov_deg < 180.0)) {
      throw invalid_parameter("camera.fov_deg", "must be in (0, 180)");
    }
    half_height_ = std::tan(camera.fov_deg * std::numbers::pi / 360.0);
    footprint_base_ = 0.0;
    footprint_slope_ = 2.0 * half_height_ / rows;
  } else {
    if (!(camera.ortho_height > 0.0) || !std::isfinite(camera.ortho_height)) {
      throw invalid_parameter("camera.ortho_height", "must be a positive finite number");
    }
    half_height_ = camera.ortho_height / 2.0;
    footprint_base_ = camera.ortho_height / rows;
    footprint_slope_ = 0.0;
  }
}

Camera orbit(const Camera& camera, double degrees) {
  if (!std::isfinite(degrees)) throw invalid_parameter("degrees", "must be finite");
  const double len = glm::length(camera.up);
  if (!finite3(camera.up) || !(len > 0.0)) {
    throw invalid_parameter("camera.up", "must be a finite non-zero vector");
  }
  // Rotates the eye's offset from the target about the unit up axis: the part along the axis
  // stays, the rest turns in the plane perpendicular to it. Written so that an axis-aligned up
  // keeps that coordinate exactly (a turntable about +y never drifts in height).
  const glm::dvec3 k = camera.up / len;
  const glm::dvec3 v = camera.eye - camera.target;
  const glm::dvec3 along = k * glm::dot(k, v);
  const double a = glm::radians(degrees);
  const glm::dvec3 rotated = along + (v - along) * std::cos(a) + glm::cross(k, v) * std::sin(a);
  Camera out = camera;
  out.eye = camera.target + rotated;
  return out;
}

Ray CameraRays::ray(double x, double y) const {
  // Image-plane coordinates in units of half heights: u to the right, v up (row 0 at the top).
  const double rows = double(viewport_.height);
  const double cols = double(viewport_.width);
  const double u = (2.0 * x - cols) / rows * half_height_;
  const double v = (rows - 2.0 * y) / rows * half_height_;
  Ray r;
  if (camera_.projection == Projection::perspective) {
    r.origin = camera_.eye;
    r.dir = glm::normalize(forward_ + u * right_ + v * up_);
  } else {
    r.origin = camera_.eye + u * right_ + v * up_;
    r.dir = forward_;
  }
  return r;
}

double CameraRays::depth(const glm::dvec3& p) const noexcept {
  return glm::dot(p - camera_.eye, forward_);
}

}  // namespace resoct
