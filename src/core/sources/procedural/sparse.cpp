// Sparse procedural fields: "tubes" (a branching tube network, mostly exactly zero) and
// "noisefloor" (blobs over a low, non-zero noise floor).
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "resoct/sources/procedural/field.hpp"
#include "resoct/sources/procedural/math.hpp"

namespace resoct::procedural {

namespace {

// Bounding box of a tensor grid (the coordinate lists need not be sorted).
void grid_bounds(std::span<const double> xs, std::span<const double> ys, std::span<const double> zs,
                 glm::dvec3& lo, glm::dvec3& hi) {
  auto mm = [](std::span<const double> v, double& a, double& b) {
    const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
    a = *mn;
    b = *mx;
  };
  mm(xs, lo.x, hi.x);
  mm(ys, lo.y, hi.y);
  mm(zs, lo.z, hi.z);
}

// A point uniform in the box [lo, hi), drawn z, then y, then x. The draws are separate
// statements because C++ leaves the order of a call's arguments unspecified (g++ evaluates
// them right to left, clang left to right), and the field must not depend on the compiler;
// z, y, x is g++'s order, which every committed result and tolerance was measured with.
glm::dvec3 uniform_point(Rng& rng, const glm::dvec3& lo, const glm::dvec3& hi) {
  const double z = rng.uniform(lo.z, hi.z);
  const double y = rng.uniform(lo.y, hi.y);
  const double x = rng.uniform(lo.x, hi.x);
  return {x, y, z};
}

glm::dvec3 random_unit(Rng& rng) {
  for (;;) {
    const glm::dvec3 v = uniform_point(rng, glm::dvec3(-1), glm::dvec3(1));
    const double l = glm::length(v);
    if (l > 0.1 && l <= 1.0) return v / l;
  }
}

struct Segment {
  glm::dvec3 a, b;   // voxel coordinates
  double radius;     // full intensity inside
  double falloff;    // smooth decay to zero over this distance beyond the radius
  double intensity;  // value inside the tube
  double reach() const noexcept { return radius + falloff; }
  double profile(double d) const noexcept {
    return intensity * smoothstep01((reach() - d) / falloff);
  }
};

class TubesField final : public Field {
 public:
  TubesField(const glm::u64vec3& extent, std::uint32_t channels) {
    const double m = double(std::max({extent.x, extent.y, extent.z}));
    const glm::dvec3 qext = glm::dvec3(extent) / m;
    for (std::uint32_t c = 0; c < channels; ++c) {
      Rng rng(0x7b1e5ull + 1000003ull * c);
      std::vector<Segment> segs;
      for (int root = 0; root < 3; ++root) {
        // Two draws, y then x (g++'s order, see uniform_point); the roots start near z = 0.
        const double y = rng.uniform(0.3, 0.7);
        const double x = rng.uniform(0.3, 0.7);
        const glm::dvec3 p = glm::dvec3(x, y, 0.05) * qext;
        const glm::dvec3 dir = glm::normalize(glm::dvec3(0, 0, 1) + 0.3 * random_unit(rng));
        grow(rng, qext, p, dir, 0.22, 0.018, 5, segs);
      }
      double lip = 0.0;
      for (Segment& s : segs) {
        s.a *= m;
        s.b *= m;
        s.radius *= m;
        s.falloff *= m;
        lip = std::max(lip, s.intensity * 1.5 / s.falloff);
      }
      segments_.push_back(std::move(segs));
      lipschitz_.push_back(lip);
    }
  }

  void eval_grid(std::uint32_t channel, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    // Tiles of kTile x kTile points per z: culling per tile keeps the candidate list short even
    // when the whole grid spans many tubes.
    constexpr std::size_t kTile = 8;
    const std::size_t nx = xs.size(), ny = ys.size();
    std::vector<const Segment*> near;
    for (std::size_t z = 0; z < zs.size(); ++z) {
      for (std::size_t y0 = 0; y0 < ny; y0 += kTile) {
        const std::size_t y1 = std::min(ny, y0 + kTile);
        for (std::size_t x0 = 0; x0 < nx; x0 += kTile) {
          const std::size_t x1 = std::min(nx, x0 + kTile);
          glm::dvec3 lo, hi;
          grid_bounds(xs.subspan(x0, x1 - x0), ys.subspan(y0, y1 - y0), zs.subspan(z, 1), lo, hi);
          const glm::dvec3 c = 0.5 * (lo + hi);
          const double hd = 0.5 * glm::length(hi - lo);
          near.clear();
          for (const Segment& s : segments_[channel]) {
            if (segment_distance(c, s.a, s.b) - hd < s.reach()) near.push_back(&s);
          }
          for (std::size_t y = y0; y < y1; ++y) {
            double* row = out.data() + (z * ny + y) * nx;
            for (std::size_t x = x0; x < x1; ++x) {
              const glm::dvec3 p(xs[x], ys[y], zs[z]);
              double v = 0.0;
              for (const Segment* s : near) {
                const double d = segment_distance(p, s->a, s->b);
                if (d < s->reach()) v = std::max(v, s->profile(d));
              }
              row[x] = v;
            }
          }
        }
      }
    }
  }

  Interval bound(std::uint32_t channel, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    const glm::dvec3 c = 0.5 * (lo + hi);
    const double hd = 0.5 * glm::length(hi - lo);
    Interval r{0.0, 0.0};
    for (const Segment& s : segments_[channel]) {
      const double d = segment_distance(c, s.a, s.b);
      if (d - hd >= s.reach()) continue;
      r.hi = std::max(r.hi, s.profile(std::max(0.0, d - hd)));
      r.lo = std::max(r.lo, s.profile(d + hd));
    }
    return r;
  }

  double lipschitz(std::uint32_t channel) const override { return lipschitz_[channel]; }

 private:
  // Grows one branch in normalized coordinates and recurses into 2 or 3 thinner children.
  static void grow(Rng& rng, const glm::dvec3& qext, const glm::dvec3& p, const glm::dvec3& dir,
                   double len, double radius, int depth, std::vector<Segment>& out) {
    // A branch about to leave the volume turns back instead of running along the border.
    glm::dvec3 d = dir;
    const glm::dvec3 lo = 0.03 * qext, hi = 0.97 * qext;
    for (int a = 0; a < 3; ++a) {
      const double e = p[a] + d[a] * len;
      if (e < lo[a] || e > hi[a]) d[a] = -d[a];
    }
    const glm::dvec3 b = glm::clamp(p + d * len, lo, hi);
    out.push_back(Segment{p, b, radius, 0.6 * radius, rng.uniform(0.55, 1.0)});
    if (depth == 0) return;
    const int children = rng.uniform() < 0.3 ? 3 : 2;
    for (int k = 0; k < children; ++k) {
      const glm::dvec3 nd = glm::normalize(d + 0.9 * random_unit(rng));
      grow(rng, qext, b, nd, len * 0.75, radius * 0.72, depth - 1, out);
    }
  }

  std::vector<std::vector<Segment>> segments_;
  std::vector<double> lipschitz_;
};

struct Blob {
  glm::dvec3 centre;  // voxel coordinates
  double radius;
  double intensity;
  double value(double d) const noexcept { return intensity * bump(d, radius); }
};

// max(floor, blobs): floor = 0.03 + 0.02 * value noise, so the background is never exactly
// zero (transparent under a sensible transfer function, but not empty).
class NoiseFloorField final : public Field {
 public:
  static constexpr double kFloorLo = 0.03;
  static constexpr double kFloorAmp = 0.02;
  static constexpr double kFloorFreq = 24.0;  // lattice cells per normalized unit

  NoiseFloorField(const glm::u64vec3& extent, std::uint32_t channels)
      : scale_(kFloorFreq / double(std::max({extent.x, extent.y, extent.z}))) {
    const double m = double(std::max({extent.x, extent.y, extent.z}));
    const glm::dvec3 qext = glm::dvec3(extent) / m;
    for (std::uint32_t c = 0; c < channels; ++c) {
      Rng rng(0xf100full + 7919ull * c);
      std::vector<Blob> blobs;
      double lip = kFloorAmp * kValueNoiseLipschitz * scale_;
      for (int k = 0; k < 48; ++k) {
        Blob b;
        b.centre = uniform_point(rng, glm::dvec3(0.1), glm::dvec3(0.9)) * qext * m;
        b.radius = rng.uniform(0.02, 0.06) * m;
        b.intensity = rng.uniform(0.4, 1.0);
        lip = std::max(lip, b.intensity * kBumpSlope / b.radius);
        blobs.push_back(b);
      }
      blobs_.push_back(std::move(blobs));
      lipschitz_.push_back(lip);
    }
  }

  void eval_grid(std::uint32_t channel, std::span<const double> xs, std::span<const double> ys,
                 std::span<const double> zs, std::span<double> out) const override {
    glm::dvec3 lo, hi;
    grid_bounds(xs, ys, zs, lo, hi);
    std::vector<const Blob*> near;
    for (const Blob& b : blobs_[channel]) {
      if (box_min_distance(b.centre, lo, hi) < b.radius) near.push_back(&b);
    }
    ValueNoise noise(0x5eedull + channel);
    std::size_t i = 0;
    for (double z : zs)
      for (double y : ys)
        for (double x : xs) {
          const glm::dvec3 p(x, y, z);
          double v = kFloorLo + kFloorAmp * noise(p * scale_);
          for (const Blob* b : near) v = std::max(v, b->value(glm::length(p - b->centre)));
          out[i++] = v;
        }
  }

  Interval bound(std::uint32_t channel, const glm::dvec3& lo, const glm::dvec3& hi) const override {
    Interval r{kFloorLo, kFloorLo + kFloorAmp};
    for (const Blob& b : blobs_[channel]) {
      r.hi = std::max(r.hi, b.value(box_min_distance(b.centre, lo, hi)));
      r.lo = std::max(r.lo, b.value(box_max_distance(b.centre, lo, hi)));
    }
    return r;
  }

  double lipschitz(std::uint32_t channel) const override { return lipschitz_[channel]; }

 private:
  double scale_;  // voxel coordinates to noise lattice units
  std::vector<std::vector<Blob>> blobs_;
  std::vector<double> lipschitz_;
};

}  // namespace

std::unique_ptr<Field> make_tubes_field(const glm::u64vec3& extent, std::uint32_t channels) {
  return std::make_unique<TubesField>(extent, channels);
}
std::unique_ptr<Field> make_noisefloor_field(const glm::u64vec3& extent, std::uint32_t channels) {
  return std::make_unique<NoiseFloorField>(extent, channels);
}

}  // namespace resoct::procedural
