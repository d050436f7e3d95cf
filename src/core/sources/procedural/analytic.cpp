// The exactly known procedural fields: constant, ramp and sphere. Tests use them for analytic
// expected values.
#include <algorithm>
#include <cmath>
#include <memory>

#include "resoct/sources/procedural/field.hpp"
#include "resoct/sources/procedural/math.hpp"

namespace resoct::procedural {

namespace {

class ConstantField final : public Field {
 public:
  void eval_grid(std::uint32_t, std::span<const double>, std::span<const double>,
                 std::span<const double>, std::span<double> out) const override {
    std::fill(out.begin(), out.end(), 0.5);
  }
  Interval bound(std::uint32_t, const glm::dvec3&, const glm::dvec3&) const override {
    return {0.5, 0.5};
  }
  double lipschitz(std::uint32_t) const override { return 0.0; }
};

// Channel c ramps along axis c % 3: v = X / extent, so voxel i holds (i + 0.5) / extent.
class RampField final : public Field {
 public:
  explicit RampField(const glm::u64vec3& extent) : extent_(extent) {}
  void eval_grid(std::uint32_t channel, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    const int axis = int(channel % 3);
    const double inv = 1.0 / double(extent_[axis]);
    std::size_t i = 0;
    for (double z : zs)
      for (double y : ys)
        for (double x : xs) {
          const double p[3] = {x, y, z};
          out[i++] = p[axis] * inv;
        }
  }
  Interval bound(std::uint32_t channel, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    const int axis = int(channel % 3);
    const double inv = 1.0 / double(extent_[axis]);
    return {lo[axis] * inv, hi[axis] * inv};
  }
  double lipschitz(std::uint32_t channel) const override {
    return 1.0 / double(extent_[channel % 3]);
  }

 private:
  glm::u64vec3 extent_;
};

// v = max(0, 1 - r / R), r the distance to the volume centre, R half the smallest extent: the
// isosurface v = t is a sphere of radius (1 - t) R.
class SphereField final : public Field {
 public:
  explicit SphereField(const glm::u64vec3& extent)
      : centre_(glm::dvec3(extent) * 0.5),
        radius_(0.5 * double(std::min({extent.x, extent.y, extent.z}))) {}
  void eval_grid(std::uint32_t, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    std::size_t i = 0;
    for (double z : zs)
      for (double y : ys)
        for (double x : xs) out[i++] = value(glm::length(glm::dvec3(x, y, z) - centre_));
  }
  Interval bound(std::uint32_t, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    return {value(box_max_distance(centre_, lo, hi)), value(box_min_distance(centre_, lo, hi))};
  }
  double lipschitz(std::uint32_t) const override { return 1.0 / radius_; }

 private:
  double value(double r) const noexcept { return std::max(0.0, 1.0 - r / radius_); }
  glm::dvec3 centre_;
  double radius_;
};

}  // namespace

std::unique_ptr<Field> make_constant_field(const glm::u64vec3&, std::uint32_t) {
  return std::make_unique<ConstantField>();
}
std::unique_ptr<Field> make_ramp_field(const glm::u64vec3& extent, std::uint32_t) {
  return std::make_unique<RampField>(extent);
}
std::unique_ptr<Field> make_sphere_field(const glm::u64vec3& extent, std::uint32_t) {
  return std::make_unique<SphereField>(extent);
}

}  // namespace resoct::procedural
