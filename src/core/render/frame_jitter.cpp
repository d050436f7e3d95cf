#include "resoct/render/frame_jitter.hpp"

#include <cmath>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

void check_unit_offset(float v, const char* name) {
  // [-0.5, 0.5): a full pixel or step would repeat the neighbour's position.
  if (!std::isfinite(v) || v < -0.5f || v >= 0.5f) {
    throw invalid_parameter(name, "must lie in [-0.5, 0.5), got " + std::to_string(v));
  }
}

}  // namespace

void FrameJitter::validate() const {
  check_unit_offset(pixel_x, "jitter.pixel_x");
  check_unit_offset(pixel_y, "jitter.pixel_y");
  check_unit_offset(sample, "jitter.sample");
}

double halton(std::uint32_t index, std::uint32_t base) noexcept {
  if (base < 2) return 0.0;
  double inv = 1.0 / double(base), f = inv, r = 0.0;
  for (std::uint32_t i = index; i > 0; i /= base) {
    r += f * double(i % base);
    f *= inv;
  }
  return r;
}

FrameJitter halton_jitter(std::uint32_t index) noexcept {
  if (index == 0) return FrameJitter{};
  // Halton(i) lies in (0, 1) for i >= 1, so each offset lies in (-0.5, 0.5); the float rounding
  // of a value just below 0.5 could reach 0.5, hence the clamp to the largest float below it.
  const auto offset = [](double h) { return std::fmin(float(h - 0.5), 0.49999997f); };
  return FrameJitter{offset(halton(index, 2)), offset(halton(index, 3)), offset(halton(index, 5))};
}

}  // namespace resoct
