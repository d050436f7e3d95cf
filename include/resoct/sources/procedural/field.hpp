#pragma once
/// \file
/// The analytic scalar fields behind the procedural datasets. A field is defined on continuous
/// level-0 voxel coordinates (voxel i's centre is i + 0.5 along each axis) and returns values in
/// [0, 1], the fraction of the channel's value range. Structures are laid out in normalized
/// coordinates q = X / max(extent), so every size shows the same shapes, only sampled finer.

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace resoct::procedural {

/// Closed interval of field values.
struct Interval {
  double lo = 0.0;
  double hi = 1.0;
};

/// One procedural dataset's values. Immutable after construction; all members are thread-safe.
class Field {
 public:
  virtual ~Field() = default;

  /// Values at every point of the tensor grid xs × ys × zs (x fastest), in level-0 voxel
  /// coordinates. `out` holds xs.size() * ys.size() * zs.size() values.
  virtual void eval_grid(std::uint32_t channel, std::span<const double> xs,
                         std::span<const double> ys, std::span<const double> zs,
                         std::span<double> out) const = 0;

  /// Conservative bounds of the field over every point of the closed box [lo, hi] (voxel
  /// coordinates): no point of the box evaluates outside the interval.
  virtual Interval bound(std::uint32_t channel, const glm::dvec3& lo,
                         const glm::dvec3& hi) const = 0;

  /// A Lipschitz constant (Euclidean, value fraction per level-0 voxel), or +infinity when none
  /// is known (mandelbulb). Coarse-level error bounds scale with it.
  virtual double lipschitz(std::uint32_t channel) const = 0;
};

/// The dataset names make_field accepts, in documentation order.
std::span<const std::string_view> field_names() noexcept;

/// Builds the field NAME for a level-0 extent and channel count (already validated by the
/// caller); nullptr for an unknown name.
std::unique_ptr<Field> make_field(std::string_view name, const glm::u64vec3& extent,
                                  std::uint32_t channels);

// Factories of the individual datasets (one translation unit each).
std::unique_ptr<Field> make_tubes_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_noisefloor_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_turbulence_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_mandelbulb_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_cells_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_constant_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_ramp_field(const glm::u64vec3& extent, std::uint32_t channels);
std::unique_ptr<Field> make_sphere_field(const glm::u64vec3& extent, std::uint32_t channels);

}  // namespace resoct::procedural
