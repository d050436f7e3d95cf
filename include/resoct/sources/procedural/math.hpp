#pragma once
/// \file
/// Small deterministic building blocks of the procedural fields: a seeded generator, lattice
/// hashing, value noise with a known gradient bound, and distance helpers. Header-only, pure
/// functions (thread-safe).

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace resoct::procedural {

/// splitmix64: the same sequence on every platform (std distributions are not portable).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() noexcept {
    std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  double uniform() noexcept { return double(next() >> 11) * 0x1.0p-53; }
  double uniform(double a, double b) noexcept { return a + (b - a) * uniform(); }

 private:
  std::uint64_t s_;
};

/// Hash of a lattice point to [0, 1).
inline double lattice_hash(std::int64_t x, std::int64_t y, std::int64_t z,
                           std::uint64_t seed) noexcept {
  Rng r(seed ^ (std::uint64_t(x) * 0x9e3779b97f4a7c15ull) ^
        (std::uint64_t(y) * 0xc2b2ae3d27d4eb4full) ^ (std::uint64_t(z) * 0x165667b19e3779f9ull));
  return r.uniform();
}

/// Quintic fade 6t^5 - 15t^4 + 10t^3; its slope is at most 15/8.
inline double fade(double t) noexcept {
  return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

/// Value noise in [0, 1] with lattice spacing 1. Each partial derivative is at most
/// 15/8 (fade slope times the largest lattice difference 1), so the gradient norm is at most
/// kValueNoiseLipschitz. Remembers the corner values of the last lattice cell, because
/// neighbouring samples mostly share it; one instance per thread and seed.
class ValueNoise {
 public:
  explicit ValueNoise(std::uint64_t seed) noexcept : seed_(seed) {}
  double operator()(const glm::dvec3& p) noexcept {
    const glm::dvec3 f = glm::floor(p);
    const std::int64_t x = std::int64_t(f.x), y = std::int64_t(f.y), z = std::int64_t(f.z);
    if (!valid_ || x != cx_ || y != cy_ || z != cz_) {
      for (int k = 0; k < 8; ++k) {
        corner_[k] = lattice_hash(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2), seed_);
      }
      cx_ = x;
      cy_ = y;
      cz_ = z;
      valid_ = true;
    }
    const glm::dvec3 t = p - f;
    const double u = fade(t.x), v = fade(t.y), w = fade(t.z);
    const double* h = corner_;
    const double x00 = h[0] + u * (h[1] - h[0]);
    const double x10 = h[2] + u * (h[3] - h[2]);
    const double x01 = h[4] + u * (h[5] - h[4]);
    const double x11 = h[6] + u * (h[7] - h[6]);
    const double y0 = x00 + v * (x10 - x00);
    const double y1 = x01 + v * (x11 - x01);
    return y0 + w * (y1 - y0);
  }

 private:
  std::uint64_t seed_;
  bool valid_ = false;
  std::int64_t cx_ = 0, cy_ = 0, cz_ = 0;
  double corner_[8] = {};
};
inline constexpr double kValueNoiseLipschitz = 1.875 * 1.7320508075688772;

/// Smoothstep 3t^2 - 2t^3 of t clamped to [0, 1]; slope at most 3/2.
inline double smoothstep01(double t) noexcept {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

/// Distance from p to the segment [a, b].
inline double segment_distance(const glm::dvec3& p, const glm::dvec3& a,
                               const glm::dvec3& b) noexcept {
  const glm::dvec3 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

/// Smallest and largest distance from point c to the closed box [lo, hi].
inline double box_min_distance(const glm::dvec3& c, const glm::dvec3& lo,
                               const glm::dvec3& hi) noexcept {
  const glm::dvec3 d = glm::max(glm::max(lo - c, c - hi), glm::dvec3(0.0));
  return glm::length(d);
}
inline double box_max_distance(const glm::dvec3& c, const glm::dvec3& lo,
                               const glm::dvec3& hi) noexcept {
  const glm::dvec3 d = glm::max(glm::abs(c - lo), glm::abs(hi - c));
  return glm::length(d);
}

/// Compact bump (1 - (d/r)^2)^2 for d < r, else 0; slope at most 1.54 / r.
inline double bump(double d, double r) noexcept {
  if (d >= r) return 0.0;
  const double u = d / r;
  const double s = 1.0 - u * u;
  return s * s;
}
inline constexpr double kBumpSlope = 1.5397;  // 8 / (3 sqrt 3) = 1.53960..., rounded up

}  // namespace resoct::procedural
