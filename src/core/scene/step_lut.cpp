#include "resoct/scene/step_lut.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

// The level index of a positive finite ratio: its bits with `shift` low bits dropped.
std::uint32_t level_bits(double ratio, std::uint32_t shift) {
  return std::bit_cast<std::uint32_t>(float(ratio)) >> shift;
}

}  // namespace

StepLevels step_levels(glm::dvec3 finest_voxel, double step_scale, float min_step, float ref_step) {
  const double h_min = std::min(finest_voxel.x, std::min(finest_voxel.y, finest_voxel.z));
  const double h_len = std::sqrt(finest_voxel.x * finest_voxel.x + finest_voxel.y * finest_voxel.y +
                                 finest_voxel.z * finest_voxel.z);
  const double floor_step = double(min_step);
  const double ref = double(ref_step);
  if (!(h_min > 0.0) || !std::isfinite(h_len) || !(step_scale > 0.0) ||
      !std::isfinite(step_scale) || !(ref > 0.0) || !std::isfinite(ref)) {
    return {};
  }
  const double lo = std::max(h_min * step_scale, floor_step) / ref;
  const double hi = std::max(h_len * step_scale, floor_step) / ref;
  // Positive normal floats only: the bit pattern then orders like the value.
  if (!(lo >= 0x1p-126) || !(hi < 0x1p127)) return {};
  for (std::uint32_t bits = kStepLevelBits;; --bits) {
    const std::uint32_t shift = 23u - bits;
    const std::uint32_t first = level_bits(lo, shift) - 1u;  // one level of margin each side
    const std::uint32_t last = level_bits(hi, shift) + 1u;
    const std::uint32_t count = last - first + 1u;
    if (count <= kMaxStepLevels) return {shift, first, count};
    if (bits == 0) return {};
  }
}

float step_level_ratio(const StepLevels& levels, std::uint32_t level) {
  return std::bit_cast<float>((levels.first + level) << levels.shift);
}

void step_lut(std::span<const glm::vec4> lut, float ratio, std::span<glm::vec4> out) {
  if (out.size() != lut.size()) {
    throw invalid_parameter(
        "out", std::to_string(out.size()) + " entries for a LUT of " + std::to_string(lut.size()));
  }
  const double r = double(ratio);
  const auto colour = [](float c) { return std::isfinite(c) && c > 0.0f ? double(c) : 0.0; };
  for (std::size_t i = 0; i < lut.size(); ++i) {
    const glm::vec4 e = lut[i];
    double a = 0.0;
    if (e.a >= 1.0f) {
      a = 1.0;
    } else if (e.a > 0.0f && r > 0.0) {
      a = std::clamp(-std::expm1(r * std::log1p(-double(e.a))), 0.0, 1.0);
    }
    out[i] =
        glm::vec4(float(colour(e.r) * a), float(colour(e.g) * a), float(colour(e.b) * a), float(a));
  }
}

}  // namespace resoct
