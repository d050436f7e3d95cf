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

// Trilinear reconstruction of the padded brick at index-space position u (voxel centres at
// integers), clamped to the brick: what the kernel's sampler computes through the halo.
class PaddedBrick {
 public:
  PaddedBrick(std::span<const std::byte> voxels, glm::uvec3 size, VoxelType type)
      : size_(size), values_(std::size_t(size.x) * size.y * size.z) {
    const std::size_t vs = voxel_size(type);
    for (std::size_t i = 0; i < values_.size(); ++i) {
      values_[i] = voxel_value(voxels.data() + i * vs, type);
    }
  }

  double at(glm::dvec3 u) const {
    int i0[3];
    double w[3];
    for (int a = 0; a < 3; ++a) {
      const double c = std::clamp(u[a], 0.0, double(size_[a] - 1));
      i0[a] = std::min(int(std::floor(c)), int(size_[a]) - 2);
      w[a] = c - double(i0[a]);
    }
    double sum = 0.0;
    for (int k = 0; k < 8; ++k) {
      const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
      const double wk =
          (dx ? w[0] : 1.0 - w[0]) * (dy ? w[1] : 1.0 - w[1]) * (dz ? w[2] : 1.0 - w[2]);
      if (wk == 0.0) continue;
      sum += wk * value(i0[0] + dx, i0[1] + dy, i0[2] + dz);
    }
    return sum;
  }

 private:
  double value(int x, int y, int z) const {
    x = std::min(x, int(size_.x) - 1);
    y = std::min(y, int(size_.y) - 1);
    z = std::min(z, int(size_.z) - 1);
    return values_[std::size_t(x) + size_.x * (std::size_t(y) + std::size_t(size_.y) * z)];
  }

  glm::uvec3 size_;
  std::vector<double> values_;
};

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

double measure_brick_error(const BrickSource& source, BrickKey key,
                           std::span<const std::byte> padded, std::uint64_t max_level0_voxels) {
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
  const double bound = spread < 0.0 ? 1.0 : std::min(1.0, spread / span);
  // Nothing measured could give a better code, or the measurement is too large to make.
  if (brick_error_code(bound) == kBrickErrorCodeBest ||
      std::uint64_t(box0.volume()) > max_level0_voxels) {
    return bound;
  }

  const PaddedBrick coarse(padded, layout.padded_size(), v.type);
  const Box3 core = h.core_box(level, key.brick());
  const glm::dvec3 scale(std::ldexp(1.0, -int(li.factor_log2.x)),
                         std::ldexp(1.0, -int(li.factor_log2.y)),
                         std::ldexp(1.0, -int(li.factor_log2.z)));
  const glm::dvec3 core_lo0(double(core.lo.x << li.factor_log2.x),
                            double(core.lo.y << li.factor_log2.y),
                            double(core.lo.z << li.factor_log2.z));
  const double halo = double(layout.halo);
  const glm::uvec3 bs = layout.brick_size;
  const glm::uvec3 ps = layout.padded_size();
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
        for (std::int64_t z = std::max(c0.lo.z, box0.lo.z); z < std::min(c0.hi.z, box0.hi.z); ++z) {
          for (std::int64_t y = std::max(c0.lo.y, box0.lo.y); y < std::min(c0.hi.y, box0.hi.y);
               ++y) {
            for (std::int64_t x = std::max(c0.lo.x, box0.lo.x); x < std::min(c0.hi.x, box0.hi.x);
                 ++x) {
              const std::size_t i =
                  std::size_t(x - c0.lo.x + layout.halo) +
                  ps.x * (std::size_t(y - c0.lo.y + layout.halo) +
                          std::size_t(ps.y) * std::size_t(z - c0.lo.z + layout.halo));
              const double v0 = voxel_value(fine.data() + i * vs, v.type);
              if (std::isnan(v0)) continue;
              const glm::dvec3 p =
                  (glm::dvec3(double(x), double(y), double(z)) - core_lo0 + 0.5) * scale + halo -
                  0.5;
              const double r = coarse.at(p);
              if (std::isnan(r)) continue;
              worst = std::max(worst, std::abs(r - v0));
            }
          }
        }
      }
    }
  }
  return std::min(1.0, worst / span);
}

}  // namespace resoct
