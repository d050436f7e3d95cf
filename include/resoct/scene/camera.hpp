#pragma once
/// \file
/// Camera model in the volume's normalized physical box, per-pixel rays and pixel footprints.
///
/// The normalized physical box has its min corner at the origin and its longest physical axis
/// spanning [0, 1]; the other axes are proportionally shorter (box_extent()). Volume-normalized
/// coordinates p in [0, 1]^3 (used by BrickHierarchy) relate to it per axis by
/// box = p * box_extent.

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/hierarchy.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

enum class Projection : std::uint8_t { perspective, orthographic };

/// "perspective" / "orthographic".
const char* to_string(Projection p) noexcept;

struct Camera {
  glm::dvec3 eye{2.0, 0.5, 0.5};
  glm::dvec3 target{0.5, 0.5, 0.5};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fov_deg = 40.0;      ///< vertical field of view, perspective only, in (0, 180)
  double ortho_height = 1.0;  ///< view height in box units, orthographic only, > 0
  Projection projection = Projection::perspective;
  friend bool operator==(const Camera&, const Camera&) = default;
};

/// The camera moved on a circle around its target: the eye turns by `degrees` about the axis
/// through the target along `up` (counter-clockwise seen from above, i.e. looking down `-up`);
/// target, up and the lens stay. Orbiting in small steps is a viewer's turntable. Throws
/// Error(invalid_argument) naming "camera.up" when up is zero or not finite, "degrees" when it
/// is not finite.
Camera orbit(const Camera& camera, double degrees);

struct Viewport {
  std::uint32_t width = 512;   ///< pixels, 1..16384
  std::uint32_t height = 512;  ///< pixels, 1..16384
  friend bool operator==(const Viewport&, const Viewport&) = default;
};

/// Origin and unit direction, in box units.
struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 dir{0.0, 0.0, 1.0};
};

/// Extent of the normalized physical box: physical_size / max(physical_size).
glm::dvec3 box_extent(const VolumeDesc& volume);
/// Volume-normalized [0, 1]^3 position of a box position.
glm::dvec3 box_to_normalized(const VolumeDesc& volume, const glm::dvec3& box_pos);
/// Box position of a volume-normalized position.
glm::dvec3 normalized_to_box(const VolumeDesc& volume, const glm::dvec3& normalized);
/// Size of one level-0 voxel in box units per axis: spacing / max(physical_size).
glm::dvec3 box_voxel_size(const VolumeDesc& volume);

/// Voxel size of level `l` in box units per axis: box_voxel_size * 2^factor_log2.
glm::dvec3 level_voxel_size(const BrickHierarchy& hierarchy, std::uint32_t l);
/// Per level, log2 of the largest voxel dimension in box units (non-decreasing): the table the
/// kernel's LOD selection reads through resoct_read_level_size_log2 (docs/rendering.md).
std::vector<float> level_size_log2_table(const BrickHierarchy& hierarchy);
/// The reference step Δ₀ of transfer-function alpha: the smallest level-0 voxel dimension in box
/// units.
double reference_step_length(const VolumeDesc& volume);

/// Ray generation for one camera and viewport. Pixel (x, y) has its centre at (x + 0.5, y + 0.5)
/// with y = 0 the top row; pixels are square (the horizontal field follows the aspect ratio).
/// Immutable; safe to share between threads.
class CameraRays {
 public:
  /// Throws Error(invalid_argument) naming "camera.*" or "viewport" when the eye equals the
  /// target, up is zero or parallel to the view direction, a value is not finite, the fov is
  /// outside (0, 180), the ortho height is not positive, or the viewport is outside 1..16384.
  CameraRays(const Camera& camera, const Viewport& viewport);

  /// The ray through the centre of pixel (x, y). Perspective rays start at the eye; orthographic
  /// rays start on the plane through the eye perpendicular to the view direction.
  Ray ray(double x, double y) const;
  Ray pixel_ray(std::uint32_t x, std::uint32_t y) const { return ray(x + 0.5, y + 0.5); }

  /// World (box-unit) size of one pixel at view depth z (distance along forward()):
  /// footprint_base() + footprint_slope() * z. Perspective: 0 + 2 tan(fov/2) / height * z (the
  /// angle per pixel); orthographic: ortho_height / height + 0.
  double footprint_base() const noexcept { return footprint_base_; }
  double footprint_slope() const noexcept { return footprint_slope_; }
  double footprint(double depth) const noexcept {
    return footprint_base_ + footprint_slope_ * (depth > 0.0 ? depth : 0.0);
  }
  /// View depth of a point: its distance from the eye along forward().
  double depth(const glm::dvec3& p) const noexcept;

  const glm::dvec3& forward() const noexcept { return forward_; }
  const glm::dvec3& right() const noexcept { return right_; }
  const glm::dvec3& up() const noexcept { return up_; }
  const Camera& camera() const noexcept { return camera_; }
  const Viewport& viewport() const noexcept { return viewport_; }

 private:
  Camera camera_;
  Viewport viewport_;
  glm::dvec3 forward_{0.0}, right_{0.0}, up_{0.0};
  double half_height_ = 0.0;  // image-plane half height at depth 1 (persp.) or in box units
  double footprint_base_ = 0.0;
  double footprint_slope_ = 0.0;
};

}  // namespace resoct
