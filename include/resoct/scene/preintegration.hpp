#pragma once
/// \file
/// Host side of pre-integrated transfer functions (kernel/preintegration.glsl.h): the per-slot
/// tables of knot values and their cumulative integrals, built from a transfer-function LUT.

#include <span>
#include <vector>

#include <glm/vec4.hpp>

namespace resoct {

/// Largest extinction per reference step in the tables: RESOCT_PREINT_TAU_MAX of the kernel
/// (kept equal by a static_assert in the tests, which include both).
inline constexpr float kPreintTauMax = 64.0f;

/// The pre-integration table of one LUT of straight-alpha RGBA entries (TransferFunction::lut;
/// alpha is the opacity of one reference step), 2 * lut.size() entries:
///   [i]             knot (r τ_i, g τ_i, b τ_i, τ_i) with τ_i = −ln(1 − α_i), capped at
///                   RESOCT_PREINT_TAU_MAX (α_i >= 1 gives the cap; α_i <= 0 or NaN gives 0)
///   [lut.size()+i]  the integral of the knots' linear interpolant from entry 0 to entry i, in
///                   units of one LUT bin (exact trapezoid sums, accumulated in double)
/// Non-finite or negative colour components count as 0. Throws Error(invalid_argument) naming
/// "lut" when it has fewer than 2 entries. Pure function; thread-safe.
std::vector<glm::vec4> preintegration_table(std::span<const glm::vec4> lut);

}  // namespace resoct
