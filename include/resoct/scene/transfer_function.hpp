#pragma once
/// \file
/// Per-channel 1D transfer functions: piecewise-linear RGBA over normalized values [0, 1], their
/// LUT for the kernel (kernel/tf.glsl.h), and the visible value set used to cull nodes.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace resoct {

/// One control point: normalized value and straight-alpha colour. Alpha is the opacity of one
/// reference step (one finest-level voxel); the renderer corrects it for the actual step.
struct TfPoint {
  double value = 0.0;
  glm::dvec4 rgba{0.0};
  friend bool operator==(const TfPoint&, const TfPoint&) = default;
};

/// Entries of a kernel LUT (RESOCT_TF_LUT_SIZE in kernel/tf.glsl.h).
inline constexpr std::uint32_t kTfLutSize = 1024;

/// Throws Error(invalid_argument) "<what>[i]: ..." unless there is at least one point, every
/// value and component is finite and in [0, 1], and values are non-decreasing (two equal values
/// make a jump). `what` is the JSON path or parameter name, e.g. "scene.json: channels[2].tf".
void validate_tf_points(const std::vector<TfPoint>& points, const std::string& what = "tf");

/// Immutable after construction; safe to share between threads.
class TransferFunction {
 public:
  /// Fully transparent everywhere.
  TransferFunction();
  /// Validates with validate_tf_points(points, "tf").
  explicit TransferFunction(std::vector<TfPoint> points);

  const std::vector<TfPoint>& points() const noexcept { return points_; }

  /// Exact piecewise-linear value at normalized v: constant beyond the first and last points, the
  /// right-hand point at a jump, transparent black for NaN; +-inf clamp to the ends.
  glm::dvec4 evaluate(double v) const;

  /// The kernel LUT: entry i = evaluate(i / (size - 1)), size >= 2.
  std::vector<glm::vec4> lut(std::uint32_t size = kTfLutSize) const;

  /// Closed normalized-value intervals, sorted and disjoint, outside which the LUT renders
  /// alpha = 0 (the kernel interpolates LUT entries linearly, so a LUT cell is visible when
  /// either end has alpha > 0). Features narrower than a LUT cell between two transparent
  /// entries are invisible to the kernel and therefore not listed either. Values outside [0, 1]
  /// clamp to the ends, so an interval touching 0 or 1 also covers everything beyond.
  const std::vector<glm::dvec2>& visible_intervals() const noexcept { return visible_; }

  /// 32-bin occupancy mask of visible_intervals(): bin b (bit b) covers [b/32, (b+1)/32), as
  /// resoct::occupancy_bit over the range [0, 1]. A node whose value-occupancy mask has no bit in
  /// common with this one renders transparent.
  std::uint32_t visible_mask() const noexcept { return mask_; }

  /// Whether some normalized value in [lo, hi] may render with alpha > 0 (false for NaN bounds or
  /// lo > hi, which describe a region without finite values).
  bool visible_in(double lo, double hi) const noexcept;

  bool fully_transparent() const noexcept { return visible_.empty(); }

  friend bool operator==(const TransferFunction& a, const TransferFunction& b) {
    return a.points_ == b.points_;
  }

 private:
  std::vector<TfPoint> points_;
  std::vector<glm::dvec2> visible_;
  std::uint32_t mask_ = 0;
};

}  // namespace resoct
