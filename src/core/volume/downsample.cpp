#include "resoct/volume/downsample.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

template <typename T>
T load(const std::byte* base, std::size_t i) {
  T v;
  std::memcpy(&v, base + i * sizeof(T), sizeof(T));
  return v;
}

template <typename T>
void store(std::byte* base, std::size_t i, T v) {
  std::memcpy(base + i * sizeof(T), &v, sizeof(T));
}

template <typename T>
T finish(double sum, std::uint32_t n) {
  if constexpr (std::is_same_v<T, float>) {
    if (n == 0) return std::numeric_limits<float>::quiet_NaN();
    return float(sum / double(n));
  } else {
    // Sums of at most 8 integer voxels are exact in double, so this is integer arithmetic.
    return T(std::floor((sum + double(n / 2)) / double(n)));
  }
}

template <typename T>
void downsample_typed(const std::byte* in, const glm::u64vec3& fe, const glm::bvec3& halve,
                      std::byte* out) {
  const glm::u64vec3 ce = downsampled_extent(fe, halve);
  const std::uint64_t sx = halve.x ? 2 : 1, sy = halve.y ? 2 : 1, sz = halve.z ? 2 : 1;
  std::size_t o = 0;
  for (std::uint64_t z = 0; z < ce.z; ++z) {
    const std::uint64_t z0 = z * sz, z1 = std::min(z0 + sz, fe.z);
    for (std::uint64_t y = 0; y < ce.y; ++y) {
      const std::uint64_t y0 = y * sy, y1 = std::min(y0 + sy, fe.y);
      for (std::uint64_t x = 0; x < ce.x; ++x, ++o) {
        const std::uint64_t x0 = x * sx, x1 = std::min(x0 + sx, fe.x);
        double sum = 0.0;
        std::uint32_t n = 0;
        for (std::uint64_t zz = z0; zz < z1; ++zz) {
          for (std::uint64_t yy = y0; yy < y1; ++yy) {
            const std::size_t row = std::size_t((zz * fe.y + yy) * fe.x);
            for (std::uint64_t xx = x0; xx < x1; ++xx) {
              const T v = load<T>(in, row + std::size_t(xx));
              if constexpr (std::is_same_v<T, float>) {
                if (std::isnan(v)) continue;
              }
              sum += double(v);
              ++n;
            }
          }
        }
        store<T>(out, o, finish<T>(sum, n));
      }
    }
  }
}

std::uint64_t voxels(const glm::u64vec3& e) {
  return e.x * e.y * e.z;
}

void check_size(std::string_view name, std::size_t got, std::uint64_t want) {
  if (got != want) {
    throw invalid_parameter(
        name, "buffer of " + std::to_string(got) + " bytes, expected " + std::to_string(want));
  }
}

}  // namespace

glm::u64vec3 downsampled_extent(const glm::u64vec3& fine_extent, const glm::bvec3& halve) noexcept {
  glm::u64vec3 e = fine_extent;
  for (int i = 0; i < 3; ++i) {
    if (halve[i]) e[i] = e[i] / 2 + e[i] % 2;
  }
  return e;
}

void downsample(std::span<const std::byte> fine, const glm::u64vec3& fine_extent,
                const glm::bvec3& halve, VoxelType t, std::span<std::byte> out) {
  const std::size_t vs = voxel_size(t);
  check_size("fine", fine.size(), voxels(fine_extent) * vs);
  check_size("out", out.size(), voxels(downsampled_extent(fine_extent, halve)) * vs);
  switch (t) {
    case VoxelType::u8:
      downsample_typed<std::uint8_t>(fine.data(), fine_extent, halve, out.data());
      break;
    case VoxelType::u16:
      downsample_typed<std::uint16_t>(fine.data(), fine_extent, halve, out.data());
      break;
    case VoxelType::f32:
      downsample_typed<float>(fine.data(), fine_extent, halve, out.data());
      break;
  }
}

void downsample_region(const Box3& coarse_box, const glm::u64vec3& fine_extent,
                       const glm::bvec3& halve, VoxelType t, const VoxelBoxReader& read_fine,
                       std::span<std::byte> out) {
  const glm::u64vec3 ce = downsampled_extent(fine_extent, halve);
  if (coarse_box.empty() || !(Box3{glm::i64vec3(0), glm::i64vec3(ce)}.contains(coarse_box.lo)) ||
      glm::any(glm::greaterThan(coarse_box.hi, glm::i64vec3(ce)))) {
    throw invalid_parameter("coarse_box", "must be a non-empty box inside the coarse level");
  }
  const std::size_t vs = voxel_size(t);
  check_size("out", out.size(), std::uint64_t(coarse_box.volume()) * vs);
  // Coarse voxels start at even fine coordinates, so the fine box is itself a whole "level"
  // whose downsampling is exactly the requested coarse box (the clamp reproduces odd ends).
  Box3 fine_box;
  for (int i = 0; i < 3; ++i) {
    const std::int64_t s = halve[i] ? 1 : 0;
    fine_box.lo[i] = coarse_box.lo[i] << s;
    fine_box.hi[i] = std::min(coarse_box.hi[i] << s, std::int64_t(fine_extent[i]));
  }
  std::vector<std::byte> fine(std::size_t(fine_box.volume()) * vs);
  read_fine(fine_box, fine);
  downsample(fine, glm::u64vec3(fine_box.size()), halve, t, out);
}

void downsample_levels(const BrickHierarchy& h, std::uint32_t from, std::uint32_t to,
                       const Box3& box, const VoxelBoxReader& read_from, std::span<std::byte> out) {
  if (from > to || to >= h.level_count()) {
    throw invalid_parameter("to", "levels must satisfy from <= to < " +
                                      std::to_string(h.level_count()) + ", got from " +
                                      std::to_string(from) + " to " + std::to_string(to));
  }
  const VoxelType t = h.volume().type;
  if (from == to) {
    const Box3 level{glm::i64vec3(0), glm::i64vec3(h.level(to).extent)};
    if (box.empty() || intersect(box, level) != box) {
      throw invalid_parameter("box", "must be a non-empty box inside the level");
    }
    check_size("out", out.size(), std::uint64_t(box.volume()) * voxel_size(t));
    read_from(box, out);
    return;
  }
  const LevelInfo& fine = h.level(to - 1);
  const glm::bvec3 halve = glm::greaterThan(h.level(to).factor_log2, fine.factor_log2);
  downsample_region(
      box, fine.extent, halve, t,
      [&](const Box3& fine_box, std::span<std::byte> fine_out) {
        downsample_levels(h, from, to - 1, fine_box, read_from, fine_out);
      },
      out);
}

}  // namespace resoct
