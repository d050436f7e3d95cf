#include "resoct/sources/brick_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {
namespace {

// The spread of the source's level-0 region answer over `box`, or nullopt-like -1 where the
// region holds no finite value.
double region_spread(const BrickSource& source, std::uint32_t channel, const Box3& box) {
  const RegionMeta m = source.region_meta(channel, box);
  if (!(m.min <= m.max)) return -1.0;
  return m.max - m.min;
}

// The padded brick's voxels as doubles, x fastest.
std::vector<double> padded_values(std::span<const std::byte> voxels, glm::uvec3 size,
                                  VoxelType type) {
  std::vector<double> out(std::size_t(size.x) * size.y * size.z);
  const std::size_t vs = voxel_size(type);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = voxel_value(voxels.data() + i * vs, type);
  return out;
}

// The trilinear reconstruction (kernel's sampler through the halo) factors into one weight per
// axis: along an axis, level-0 coordinate x lies at padded index-space position
// u = (x - core_lo0 + 1/2) 2^-f + halo - 1/2 (voxel centres at integers), clamped to the brick,
// between voxels i0 and i0 + 1 with weight w on the second. Tabled per coordinate of the box.
struct AxisTaps {
  std::int64_t lo = 0;           // first level-0 coordinate tabled
  std::vector<std::int32_t> i0;  // per coordinate: the lower voxel
  std::vector<double> w;         // and the upper voxel's weight, in [0, 1]
};

AxisTaps axis_taps(std::int64_t lo, std::int64_t hi, double core_lo0, double scale, double halo,
                   std::uint32_t size) {
  AxisTaps t;
  t.lo = lo;
  for (std::int64_t x = lo; x < hi; ++x) {
    const double u = (double(x) - core_lo0 + 0.5) * scale + halo - 0.5;
    const double c = std::clamp(u, 0.0, double(size - 1));
    const int i0 = std::min(int(std::floor(c)), int(size) - 2);
    t.i0.push_back(i0);
    t.w.push_back(c - double(i0));
  }
  return t;
}

// (1 - w) a + w b over the taps whose weight is not zero: a NaN voxel the reconstruction gives
// no weight does not reach the result.
double lerp_taps(double a, double b, double w) noexcept {
  if (w == 0.0) return a;
  if (w == 1.0) return b;
  return (1.0 - w) * a + w * b;
}

// The largest, over level-0 coordinates x of [lo, hi) along one axis, weighted second moment of
// (q - x - 1/2) over the level-0 voxel centres q the reconstruction at x + 1/2 draws on (see
// lipschitz_brick_error_bound). `taps` index the padded brick; padded index i is level-l voxel
// clamp(core_lo + i - halo) (read_brick repeats border voxels), whose footprint is
// [j f, min((j + 1) f, extent0)).
double axis_second_moment(const AxisTaps& taps, std::int64_t core_lo, std::int64_t halo,
                          std::uint32_t factor_log2, std::uint64_t level_extent,
                          std::uint64_t extent0) {
  const double f = std::ldexp(1.0, int(factor_log2));
  const auto footprint_moment = [&](std::int64_t i, double p) {
    const std::int64_t j =
        std::clamp<std::int64_t>(core_lo + i - halo, 0, std::int64_t(level_extent) - 1);
    const double lo = std::ldexp(double(j), int(factor_log2));
    const double hi = std::ldexp(double(j + 1), int(factor_log2));
    if (hi <= double(extent0)) {
      const double d = lo + 0.5 * f - p;
      return (f * f - 1.0) / 12.0 + d * d;
    }
    const double a = lo + 0.5 - p;
    const double b = double(extent0) - 0.5 - p;
    return std::max(a * a, b * b);
  };
  double worst = 0.0;
  for (std::size_t k = 0; k < taps.w.size(); ++k) {
    const double p = double(taps.lo + std::int64_t(k)) + 0.5;
    const double w = taps.w[k];
    double m = 0.0;
    if (w != 1.0) m += (1.0 - w) * footprint_moment(taps.i0[k], p);
    if (w != 0.0) m += w * footprint_moment(taps.i0[k] + 1, p);
    worst = std::max(worst, m);
  }
  return worst;
}

}  // namespace

std::uint32_t brick_error_code(double error) noexcept {
  if (!(error < 1.0)) return 0;  // also NaN
  if (error <= 0.0) return kBrickErrorCodeBest;
  // The largest k with error <= 2^-k: floor(-log2(error)), corrected for log2's rounding.
  int k = int(std::floor(-std::log2(error)));
  while (k > 0 && error > std::ldexp(1.0, -k)) --k;
  while (k < 15 && error <= std::ldexp(1.0, -(k + 1))) ++k;
  return std::uint32_t(std::clamp(k, 0, 15));
}

float brick_error_to_float(double error) noexcept {
  const float f = float(error);
  if (double(f) < error) return std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

double lipschitz_brick_error_bound(const BrickHierarchy& h, BrickKey key,
                                   const LipschitzErrorTerms& terms) {
  if (!h.contains(key)) {
    throw Error(ErrorCode::out_of_range, "lipschitz_brick_error_bound: parameter 'key': level " +
                                             std::to_string(key.level()) + " channel " +
                                             std::to_string(key.channel()) +
                                             " is not a brick of the hierarchy");
  }
  const std::uint32_t level = key.level();
  if (level == 0) return 0.0;
  const VolumeDesc& v = h.volume();
  const ValueRange range = v.range(key.channel());
  const double span = range.hi - range.lo;
  if (!(span > 0.0) || !std::isfinite(span)) return 1.0;
  if (!(terms.lipschitz >= 0.0 && std::isfinite(terms.lipschitz))) return 1.0;
  const Box3 box0 = h.level0_box(level, key.brick());
  if (box0.empty()) return 0.0;
  const BrickLayout& layout = h.layout();
  const LevelInfo& li = h.level(level);
  const Box3 core = h.core_box(level, key.brick());
  const glm::uvec3 ps = layout.padded_size();
  double moment = 0.0;
  for (int a = 0; a < 3; ++a) {
    const AxisTaps taps =
        axis_taps(box0.lo[a], box0.hi[a], double(core.lo[a] << li.factor_log2[a]),
                  std::ldexp(1.0, -int(li.factor_log2[a])), double(layout.halo), ps[a]);
    moment += axis_second_moment(taps, core.lo[a], std::int64_t(layout.halo), li.factor_log2[a],
                                 li.extent[a], v.extent[a]);
  }
  const double e =
      terms.level_error + 2.0 * terms.voxel_error + terms.lipschitz * std::sqrt(moment);
  return std::min(1.0, e / span);
}

double measure_brick_error(const BrickSource& source, BrickKey key,
                           std::span<const std::byte> padded, std::uint64_t max_level0_voxels,
                           double known_bound) {
  const BrickHierarchy& h = source.hierarchy();
  const BrickLayout& layout = h.layout();
  const VolumeDesc& v = h.volume();
  const std::size_t vs = voxel_size(v.type);
  if (padded.size() != layout.padded_voxels() * vs) {
    throw invalid_parameter("padded", std::to_string(padded.size()) + " bytes, a padded brick of " +
                                          source.name() + " has " +
                                          std::to_string(layout.padded_voxels() * vs));
  }
  const std::uint32_t level = key.level();
  if (level == 0) return 0.0;
  const ValueRange range = v.range(key.channel());
  const double span = range.hi - range.lo;
  if (!(span > 0.0) || !std::isfinite(span)) return 1.0;
  const LevelInfo& li = h.level(level);
  const Box3 box0 = h.level0_box(level, key.brick());
  if (box0.empty()) return 0.0;

  // The metadata bound (see the header): the spread over the core's level-0 box dilated by one
  // level-l voxel.
  Box3 wide = box0;
  for (int a = 0; a < 3; ++a) {
    const std::int64_t step = std::int64_t(1) << li.factor_log2[a];
    wide.lo[a] = std::max<std::int64_t>(0, box0.lo[a] - step);
    wide.hi[a] = std::min<std::int64_t>(std::int64_t(v.extent[a]), box0.hi[a] + step);
  }
  const double spread = region_spread(source, key.channel(), wide);
  const double cap = std::min(1.0, std::max(0.0, known_bound));
  const double bound = std::min(cap, spread < 0.0 ? 1.0 : spread / span);
  // Nothing measured could give a better code, or the measurement is too large to make.
  if (brick_error_code(bound) == kBrickErrorCodeBest ||
      std::uint64_t(box0.volume()) > max_level0_voxels) {
    return bound;
  }

  const glm::uvec3 bs = layout.brick_size;
  const glm::uvec3 ps = layout.padded_size();
  const std::vector<double> coarse = padded_values(padded, ps, v.type);
  const Box3 core = h.core_box(level, key.brick());
  const double halo = double(layout.halo);
  AxisTaps taps[3];
  for (int a = 0; a < 3; ++a) {
    taps[a] = axis_taps(box0.lo[a], box0.hi[a], double(core.lo[a] << li.factor_log2[a]),
                        std::ldexp(1.0, -int(li.factor_log2[a])), halo, ps[a]);
  }
  // Separable passes per level-0 brick: the coarse voxels its box needs interpolated along z per
  // level-0 z (a slab), the slab along y per level-0 row, the row along x per voxel; one lerp
  // per level-0 voxel instead of eight weighted taps.
  std::vector<double> slab;
  std::vector<double> row;
  std::vector<std::byte> fine(layout.padded_voxels() * vs);
  double worst = 0.0;
  // The level-0 bricks under the footprint, each read whole and compared at its core voxels.
  const glm::u64vec3 b_lo = glm::u64vec3(box0.lo) / glm::u64vec3(bs);
  const glm::u64vec3 b_hi =
      (glm::u64vec3(box0.hi) + glm::u64vec3(bs) - glm::u64vec3(1)) / glm::u64vec3(bs);
  for (std::uint64_t bz = b_lo.z; bz < b_hi.z; ++bz) {
    for (std::uint64_t by = b_lo.y; by < b_hi.y; ++by) {
      for (std::uint64_t bx = b_lo.x; bx < b_hi.x; ++bx) {
        const glm::uvec3 b{std::uint32_t(bx), std::uint32_t(by), std::uint32_t(bz)};
        source.read_brick(BrickKey(0, key.channel(), b), fine);
        const Box3 c0 = h.core_box(0, b);
        const glm::i64vec3 lo = glm::max(c0.lo, box0.lo);
        const glm::i64vec3 hi = glm::min(c0.hi, box0.hi);
        if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) continue;
        // The coarse voxels these level-0 voxels interpolate: [cx0, cx1] x [cy0, cy1].
        const int cx0 = taps[0].i0[std::size_t(lo.x - taps[0].lo)];
        const int cx1 = taps[0].i0[std::size_t(hi.x - 1 - taps[0].lo)] + 1;
        const int cy0 = taps[1].i0[std::size_t(lo.y - taps[1].lo)];
        const int cy1 = taps[1].i0[std::size_t(hi.y - 1 - taps[1].lo)] + 1;
        const std::size_t nx = std::size_t(cx1 - cx0 + 1);
        const std::size_t ny = std::size_t(cy1 - cy0 + 1);
        slab.resize(nx * ny);
        row.resize(nx);
        for (std::int64_t z = lo.z; z < hi.z; ++z) {
          const std::size_t tz = std::size_t(z - taps[2].lo);
          const std::size_t z0 = std::size_t(taps[2].i0[tz]);
          const double wz = taps[2].w[tz];
          for (std::size_t y = 0; y < ny; ++y) {
            const std::size_t r0 = std::size_t(cx0) + ps.x * (std::size_t(cy0) + y + ps.y * z0);
            const std::size_t r1 = r0 + std::size_t(ps.x) * ps.y;
            for (std::size_t x = 0; x < nx; ++x) {
              slab[x + nx * y] = lerp_taps(coarse[r0 + x], coarse[r1 + x], wz);
            }
          }
          for (std::int64_t y = lo.y; y < hi.y; ++y) {
            const std::size_t ty = std::size_t(y - taps[1].lo);
            const std::size_t y0 = std::size_t(taps[1].i0[ty] - cy0);
            const double wy = taps[1].w[ty];
            for (std::size_t x = 0; x < nx; ++x) {
              row[x] = lerp_taps(slab[x + nx * y0], slab[x + nx * (y0 + 1)], wy);
            }
            const std::size_t line =
                ps.x * (std::size_t(y - c0.lo.y + layout.halo) +
                        std::size_t(ps.y) * std::size_t(z - c0.lo.z + layout.halo));
            for (std::int64_t x = lo.x; x < hi.x; ++x) {
              const std::size_t i = std::size_t(x - c0.lo.x + layout.halo) + line;
              const double v0 = voxel_value(fine.data() + i * vs, v.type);
              if (std::isnan(v0)) continue;
              const std::size_t tx = std::size_t(x - taps[0].lo);
              const std::size_t x0 = std::size_t(taps[0].i0[tx] - cx0);
              const double r = lerp_taps(row[x0], row[x0 + 1], taps[0].w[tx]);
              if (std::isnan(r)) continue;
              worst = std::max(worst, std::abs(r - v0));
            }
          }
        }
      }
    }
  }
  return std::min(cap, worst / span);
}

}  // namespace resoct
