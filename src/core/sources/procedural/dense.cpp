// Dense procedural fields: "turbulence" (fractal value-noise fBm) and "mandelbulb" (a shell
// around the power-8 Mandelbulb from its distance estimate).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "resoct/sources/procedural/field.hpp"
#include "resoct/sources/procedural/math.hpp"

namespace resoct::procedural {

namespace {

// v = clamp(0.5 + kContrast * fbm / sum(a), 0, 1) with fbm = sum_o a_o (2 n(F_o q) - 1).
class TurbulenceField final : public Field {
 public:
  static constexpr int kOctaves = 4;
  static constexpr double kBaseFreq = 2.0;  // lattice cells per normalized unit
  static constexpr double kContrast = 0.9;

  explicit TurbulenceField(const glm::u64vec3& extent)
      : scale_(1.0 / double(std::max({extent.x, extent.y, extent.z}))) {
    double amp = 1.0, freq = kBaseFreq, sum = 0.0, slope = 0.0;
    for (int o = 0; o < kOctaves; ++o) {
      sum += amp;
      slope += amp * 2.0 * freq * kValueNoiseLipschitz;
      amp *= 0.5;
      freq *= 2.0;
    }
    norm_ = kContrast / sum;
    lipschitz_ = norm_ * slope * scale_;
  }

  void eval_grid(std::uint32_t channel, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    Octaves noise = octaves(channel);
    std::size_t i = 0;
    for (double z : zs)
      for (double y : ys)
        for (double x : xs) out[i++] = value(noise, glm::dvec3(x, y, z));
  }

  Interval bound(std::uint32_t channel, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    Octaves noise = octaves(channel);
    const double v = value(noise, 0.5 * (lo + hi));
    const double r = lipschitz_ * 0.5 * glm::length(hi - lo);
    return {std::max(0.0, v - r), std::min(1.0, v + r)};
  }

  double lipschitz(std::uint32_t) const override { return lipschitz_; }

 private:
  using Octaves = std::array<ValueNoise, kOctaves>;
  static Octaves octaves(std::uint32_t channel) noexcept {
    const std::uint64_t seed = 0x7a5bull + 131ull * channel;
    return {ValueNoise(seed), ValueNoise(seed), ValueNoise(seed), ValueNoise(seed)};
  }

  double value(Octaves& noise, const glm::dvec3& x) const noexcept {
    const glm::dvec3 q = x * scale_;
    double amp = 1.0, freq = kBaseFreq, fbm = 0.0;
    for (int o = 0; o < kOctaves; ++o) {
      // Per-octave offsets keep lattice points of different octaves from coinciding.
      const glm::dvec3 off(17.31 * o, 5.77 * o, 11.13 * o);
      fbm += amp * (2.0 * noise[std::size_t(o)](q * freq + off) - 1.0);
      amp *= 0.5;
      freq *= 2.0;
    }
    return std::clamp(0.5 + norm_ * fbm, 0.0, 1.0);
  }

  double scale_;
  double norm_ = 0.0;
  double lipschitz_ = 0.0;
};

struct Complex {
  double re, im;
};

// u^n by squaring: cos(n a) + i sin(n a) for u = cos a + i sin a.
Complex cpow(Complex u, int n) noexcept {
  Complex r{1.0, 0.0};
  while (n > 0) {
    if (n & 1) r = {r.re * u.re - r.im * u.im, r.re * u.im + r.im * u.re};
    u = {u.re * u.re - u.im * u.im, 2.0 * u.re * u.im};
    n >>= 1;
  }
  return r;
}

double ipow(double x, int n) noexcept {
  double r = 1.0;
  while (n > 0) {
    if (n & 1) r *= x;
    x *= x;
    n >>= 1;
  }
  return r;
}

// The bulb is centred in the volume and scaled so that normalized distance 0.5 is kSpan / 2.
// v = smoothstep(1 - DE / kShell) inside radius kCutoff and exactly 0 outside, so region bounds
// can prove emptiness away from the bulb.
class MandelbulbField final : public Field {
 public:
  static constexpr double kSpan = 2.6;
  static constexpr double kShell = 0.02;
  static constexpr double kCutoff = 1.25;
  static constexpr int kIterations = 10;

  explicit MandelbulbField(const glm::u64vec3& extent)
      : centre_(glm::dvec3(extent) * 0.5),
        scale_(kSpan / double(std::max({extent.x, extent.y, extent.z}))) {}

  void eval_grid(std::uint32_t channel, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    std::size_t i = 0;
    for (double z : zs)
      for (double y : ys)
        for (double x : xs) out[i++] = value(channel, glm::dvec3(x, y, z));
  }

  Interval bound(std::uint32_t, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    if (box_min_distance(centre_, lo, hi) * scale_ > kCutoff) return {0.0, 0.0};
    return {0.0, 1.0};
  }

  double lipschitz(std::uint32_t) const override { return std::numeric_limits<double>::infinity(); }

 private:
  double value(std::uint32_t channel, const glm::dvec3& x) const noexcept {
    const glm::dvec3 c = (x - centre_) * scale_;
    if (glm::length(c) > kCutoff) return 0.0;
    // Channel c is the power-(8 + c) bulb. Integer powers allow the angle multiplication to be
    // done as complex powers of (cos, sin), without trigonometric calls.
    const int power = 8 + int(channel);
    glm::dvec3 z = c;
    double dr = 1.0, r = 0.0;
    bool escaped = false;
    for (int i = 0; i < kIterations; ++i) {
      r = glm::length(z);
      if (r > 2.0) {
        escaped = true;
        break;
      }
      if (r < 1e-12) {
        z = c;
        continue;
      }
      const double rho = std::sqrt(z.x * z.x + z.y * z.y);
      const Complex theta = cpow({z.z / r, rho / r}, power);
      const Complex phi =
          cpow(rho > 0.0 ? Complex{z.x / rho, z.y / rho} : Complex{1.0, 0.0}, power);
      const double rp = ipow(r, power - 1);
      dr = rp * double(power) * dr + 1.0;
      const double zr = rp * r;
      z = zr * glm::dvec3(theta.im * phi.re, theta.im * phi.im, theta.re) + c;
    }
    if (!escaped) return 1.0;
    const double de = 0.5 * std::log(r) * r / dr;
    return smoothstep01(1.0 - de / kShell);
  }

  glm::dvec3 centre_;
  double scale_;
};

}  // namespace

std::unique_ptr<Field> make_turbulence_field(const glm::u64vec3& extent, std::uint32_t) {
  return std::make_unique<TurbulenceField>(extent);
}
std::unique_ptr<Field> make_mandelbulb_field(const glm::u64vec3& extent, std::uint32_t) {
  return std::make_unique<MandelbulbField>(extent);
}

}  // namespace resoct::procedural
