#include "resoct/scene/transfer_function.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "resoct/base/error.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {
namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

[[noreturn]] void fail(const std::string& what, std::size_t i, const std::string& why) {
  throw Error(ErrorCode::invalid_argument, what + "[" + std::to_string(i) + "]: " + why);
}

bool unit(double v) {
  return std::isfinite(v) && v >= 0.0 && v <= 1.0;
}

}  // namespace

void validate_tf_points(const std::vector<TfPoint>& points, const std::string& what) {
  if (points.empty()) {
    throw Error(ErrorCode::invalid_argument, what + ": needs at least one point");
  }
  static constexpr const char* kComponent[4] = {"red", "green", "blue", "alpha"};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const TfPoint& p = points[i];
    if (!unit(p.value)) fail(what, i, "value " + fmt(p.value) + " outside [0,1]");
    for (int c = 0; c < 4; ++c) {
      if (!unit(p.rgba[c])) {
        fail(what, i, std::string(kComponent[c]) + " " + fmt(p.rgba[c]) + " outside [0,1]");
      }
    }
    if (i > 0 && p.value < points[i - 1].value) {
      fail(what, i,
           "value " + fmt(p.value) + " below the previous " + fmt(points[i - 1].value) +
               " (values must be ascending)");
    }
  }
}

TransferFunction::TransferFunction() : points_{TfPoint{0.0, glm::dvec4(0.0)}} {}

TransferFunction::TransferFunction(std::vector<TfPoint> points) : points_(std::move(points)) {
  validate_tf_points(points_, "tf");
  // The visible set follows the LUT the kernel interpolates, not the exact function, so culling
  // agrees with what the kernel would render.
  const std::vector<glm::vec4> table = lut(kTfLutSize);
  const double cell = 1.0 / double(kTfLutSize - 1);
  for (std::uint32_t i = 0; i + 1 < kTfLutSize; ++i) {
    if (!(table[i].a > 0.0f) && !(table[i + 1].a > 0.0f)) continue;
    const double lo = i * cell;
    const double hi = i + 2 == kTfLutSize ? 1.0 : (i + 1) * cell;
    if (!visible_.empty() && visible_.back().y >= lo) {
      visible_.back().y = hi;
    } else {
      visible_.push_back({lo, hi});
    }
  }
  const ValueRange unit_range{0.0, 1.0};
  for (const glm::dvec2& iv : visible_) mask_ |= occupancy_span(iv.x, iv.y, unit_range);
}

glm::dvec4 TransferFunction::evaluate(double v) const {
  if (std::isnan(v)) return glm::dvec4(0.0);
  // First point strictly above v: v lies in [prev.value, next.value), so at a jump (two equal
  // values) the right-hand point wins.
  const auto next = std::upper_bound(points_.begin(), points_.end(), v,
                                     [](double x, const TfPoint& p) { return x < p.value; });
  if (next == points_.begin()) return points_.front().rgba;
  if (next == points_.end()) return points_.back().rgba;
  const TfPoint& a = *(next - 1);
  const TfPoint& b = *next;
  const double f = (v - a.value) / (b.value - a.value);
  return a.rgba + (b.rgba - a.rgba) * f;
}

std::vector<glm::vec4> TransferFunction::lut(std::uint32_t size) const {
  if (size < 2) throw invalid_parameter("lut size", "must be at least 2");
  std::vector<glm::vec4> out(size);
  for (std::uint32_t i = 0; i < size; ++i) {
    out[i] = glm::vec4(evaluate(double(i) / double(size - 1)));
  }
  return out;
}

bool TransferFunction::visible_in(double lo, double hi) const noexcept {
  if (std::isnan(lo) || std::isnan(hi) || lo > hi) return false;
  // Values beyond [0, 1] render like the ends.
  lo = std::clamp(lo, 0.0, 1.0);
  hi = std::clamp(hi, 0.0, 1.0);
  return std::any_of(visible_.begin(), visible_.end(),
                     [&](const glm::dvec2& iv) { return iv.x <= hi && lo <= iv.y; });
}

}  // namespace resoct
