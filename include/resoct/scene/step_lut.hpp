#pragma once
/// \file
/// Host side of the step levels (kernel/step_lut.glsl.h): which levels a frame's rays can have,
/// and the opacity-corrected, premultiplied transfer-function LUT of one level.

#include <cstdint>
#include <span>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace resoct {

/// The step levels of a frame: a ray's full-step ratio Δ/Δ₀ is rounded down to the float whose
/// bits are its bits >> shift << shift; levels first .. first + count − 1 have LUTs. count = 0:
/// none (every sample corrects its opacity).
struct StepLevels {
  std::uint32_t shift = 0;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  bool operator==(const StepLevels&) const = default;
};

/// Most levels a frame's tables hold: 16 KiB of LUT per level and shown channel.
inline constexpr std::uint32_t kMaxStepLevels = 48;
/// Levels per octave when the range allows (2^5: a step at most 1/32 shorter than Eq. 8.3's).
inline constexpr std::uint32_t kStepLevelBits = 5;

/// The levels every ray of a frame can have: the kernel's step (kernel/step.glsl.h) along any
/// unit direction lies in [min_i h_i, |h|] · step_scale (h = the finest voxel size in box units,
/// per axis), at least min_step; its ratio to ref_step is rounded down to 2^kStepLevelBits levels
/// per octave, fewer when that would exceed kMaxStepLevels, with one level of margin on each
/// side for float rounding. count = 0 when the parameters are not positive and finite.
StepLevels step_levels(glm::dvec3 finest_voxel, double step_scale, float min_step, float ref_step);

/// The ratio Δ/Δ₀ of level `level` (< levels.count), as the kernel computes it.
float step_level_ratio(const StepLevels& levels, std::uint32_t level);

/// The LUT of one level: entry i is straight-alpha entry lut[i] with its alpha α corrected to
/// 1 − (1 − α)^ratio and its colour multiplied by that (in double; α >= 1 gives 1, α <= 0 or
/// NaN gives 0, non-finite or negative colour components count as 0). `out` has lut.size()
/// entries. Throws Error(invalid_argument) naming "out" when the sizes differ.
void step_lut(std::span<const glm::vec4> lut, float ratio, std::span<glm::vec4> out);

}  // namespace resoct
