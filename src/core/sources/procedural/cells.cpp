// "cells": a slab of cell-like blobs seen through many marker channels, modelled on multiplexed
// tissue imaging (CyCIF). Cells sit on a jittered grid in x/y inside the slab; channel 0 stains
// every nucleus, channel c >= 1 lights only the cells positive for marker c, as a filled
// cytoplasm, a membrane ring or a nucleus depending on c % 3.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "resoct/sources/procedural/field.hpp"
#include "resoct/sources/procedural/math.hpp"

namespace resoct::procedural {

namespace {

enum class Pattern { cytoplasm, membrane, nucleus };

struct Cell {
  glm::dvec3 centre;  // voxel coordinates
  double radius;      // cell radius; the nucleus has half of it
  double intensity;   // channel-specific brightness, 0 when the cell is negative
  Pattern pattern;

  double profile(double d) const noexcept {
    switch (pattern) {
      case Pattern::cytoplasm: return intensity * bump(d, radius);
      case Pattern::nucleus: return intensity * bump(d, 0.5 * radius);
      case Pattern::membrane: return intensity * bump(std::abs(d - 0.8 * radius), 0.2 * radius);
    }
    return 0.0;
  }
  // Largest profile value over distances [a, b].
  double peak(double a, double b) const noexcept {
    if (pattern == Pattern::membrane && a <= 0.8 * radius && 0.8 * radius <= b) return intensity;
    return pattern == Pattern::membrane ? std::max(profile(a), profile(b)) : profile(a);
  }
};

class CellsField final : public Field {
 public:
  static constexpr double kSpacing = 0.025;  // grid pitch in normalized units
  static constexpr double kMinRadius = 0.28 * kSpacing;
  static constexpr double kMaxRadius = 0.40 * kSpacing;

  explicit CellsField(const glm::u64vec3& extent)
      : m_(double(std::max({extent.x, extent.y, extent.z}))),
        qext_(glm::dvec3(extent) / m_),
        pitch_(kSpacing * m_) {}

  void eval_grid(std::uint32_t channel, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    // Cells of the grid cells under the points' box, one cell of margin: every cell that can
    // reach a point (jitter 0.25 + radius 0.4 < 1 pitch) is in the table.
    const auto [xmin, xmax] = std::minmax_element(xs.begin(), xs.end());
    const auto [ymin, ymax] = std::minmax_element(ys.begin(), ys.end());
    const std::int64_t i0 = std::int64_t(std::floor(*xmin / pitch_)) - 1;
    const std::int64_t j0 = std::int64_t(std::floor(*ymin / pitch_)) - 1;
    const std::int64_t ni = std::int64_t(std::floor(*xmax / pitch_)) + 2 - i0;
    const std::int64_t nj = std::int64_t(std::floor(*ymax / pitch_)) + 2 - j0;
    std::vector<Cell> table(std::size_t(ni * nj));
    for (std::int64_t j = 0; j < nj; ++j)
      for (std::int64_t i = 0; i < ni; ++i)
        table[std::size_t(j * ni + i)] = cell(i0 + i, j0 + j, channel);
    std::size_t o = 0;
    for (double z : zs)
      for (double y : ys) {
        const std::int64_t cj = std::int64_t(std::floor(y / pitch_)) - j0;
        for (double x : xs) {
          const std::int64_t ci = std::int64_t(std::floor(x / pitch_)) - i0;
          const glm::dvec3 p(x, y, z);
          double v = 0.0;
          for (std::int64_t dj = -1; dj <= 1; ++dj)
            for (std::int64_t di = -1; di <= 1; ++di) {
              const Cell& c = table[std::size_t((cj + dj) * ni + ci + di)];
              if (c.intensity > 0.0) v = std::max(v, c.profile(glm::length(p - c.centre)));
            }
          out[o++] = v;
        }
      }
  }

  Interval bound(std::uint32_t channel, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    const std::int64_t i0 = std::int64_t(std::floor(lo.x / pitch_)) - 1;
    const std::int64_t j0 = std::int64_t(std::floor(lo.y / pitch_)) - 1;
    const std::int64_t i1 = std::int64_t(std::floor(hi.x / pitch_)) + 1;
    const std::int64_t j1 = std::int64_t(std::floor(hi.y / pitch_)) + 1;
    // Large boxes: the cap keeps queries cheap; [0, 1] is always true.
    if ((i1 - i0 + 1) * (j1 - j0 + 1) > 4096) return {0.0, 1.0};
    Interval r{0.0, 0.0};
    for (std::int64_t j = j0; j <= j1; ++j)
      for (std::int64_t i = i0; i <= i1; ++i) {
        const Cell c = cell(i, j, channel);
        if (c.intensity <= 0.0) continue;
        r.hi = std::max(
            r.hi, c.peak(box_min_distance(c.centre, lo, hi), box_max_distance(c.centre, lo, hi)));
      }
    return r;
  }

  // Steepest profile: the membrane ring, width 0.2 r of the smallest cell.
  double lipschitz(std::uint32_t) const override { return kBumpSlope / (0.2 * kMinRadius * m_); }

 private:
  Cell cell(std::int64_t i, std::int64_t j, std::uint32_t channel) const noexcept {
    auto h = [&](std::int64_t salt) { return lattice_hash(i, j, salt, 0xce11ull); };
    Cell c;
    c.centre =
        glm::dvec3((double(i) + 0.25 + 0.5 * h(1)) * pitch_,
                   (double(j) + 0.25 + 0.5 * h(2)) * pitch_, qext_.z * (0.3 + 0.4 * h(3)) * m_);
    c.radius = (kMinRadius + (kMaxRadius - kMinRadius) * h(4)) * m_;
    // Cells outside the slab's x/y extent do not exist.
    if (c.centre.x < 0.0 || c.centre.y < 0.0 || c.centre.x > qext_.x * m_ ||
        c.centre.y > qext_.y * m_) {
      c.intensity = 0.0;
      c.pattern = Pattern::nucleus;
      return c;
    }
    if (channel == 0) {
      c.pattern = Pattern::nucleus;
      c.intensity = 0.6 + 0.4 * h(5);
      return c;
    }
    c.pattern = Pattern(channel % 3);
    // Each marker is positive in its own fraction (15-55 %) of the cells.
    const double fraction = 0.15 + 0.1 * double((channel * 7) % 5);
    const bool positive = h(100 + std::int64_t(channel)) < fraction;
    c.intensity = positive ? 0.45 + 0.55 * h(200 + std::int64_t(channel)) : 0.0;
    return c;
  }

  double m_;
  glm::dvec3 qext_;
  double pitch_;  // grid pitch in voxels
};

}  // namespace

std::unique_ptr<Field> make_cells_field(const glm::u64vec3& extent, std::uint32_t) {
  return std::make_unique<CellsField>(extent);
}

}  // namespace resoct::procedural
