#include "resoct/scene/preintegration.hpp"

#include <algorithm>
#include <cmath>

#include <glm/vec4.hpp>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

// Extinction per reference step of a reference-step opacity; opaque entries get the kernel's cap
// so that cumulative sums stay finite.
double extinction(float alpha) {
  const double cap = double(kPreintTauMax);
  if (!(alpha > 0.0f)) return 0.0;
  if (alpha >= 1.0f) return cap;
  return std::min(-std::log1p(-double(alpha)), cap);
}

double component(float c) {
  return std::isfinite(c) && c > 0.0f ? double(c) : 0.0;
}

}  // namespace

std::vector<glm::vec4> preintegration_table(std::span<const glm::vec4> lut) {
  if (lut.size() < 2) throw invalid_parameter("lut", "needs at least 2 entries");
  const std::size_t n = lut.size();
  std::vector<glm::dvec4> knots(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double tau = extinction(lut[i].a);
    knots[i] = glm::dvec4(component(lut[i].r) * tau, component(lut[i].g) * tau,
                          component(lut[i].b) * tau, tau);
  }
  std::vector<glm::vec4> out(2 * n);
  glm::dvec4 sum(0.0);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = glm::vec4(knots[i]);
    out[n + i] = glm::vec4(sum);
    if (i + 1 < n) sum += 0.5 * (knots[i] + knots[i + 1]);
  }
  return out;
}

}  // namespace resoct
