#include "support/reference_levels.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace resoct::test {

std::vector<RefLevel> reference_levels(const BrickHierarchy& h, const std::vector<double>& level0,
                                       VoxelType t) {
  std::vector<RefLevel> out(h.level_count());
  out[0].extent = h.level(0).extent;
  out[0].v = level0;
  for (std::uint32_t l = 1; l < h.level_count(); ++l) {
    const RefLevel& fine = out[l - 1];
    RefLevel& coarse = out[l];
    coarse.extent = h.level(l).extent;
    coarse.v.resize(std::size_t(coarse.extent.x * coarse.extent.y * coarse.extent.z));
    glm::u64vec3 step;
    for (int a = 0; a < 3; ++a) {
      step[a] = h.level(l).factor_log2[a] > h.level(l - 1).factor_log2[a] ? 2 : 1;
    }
    for (std::uint64_t z = 0; z < coarse.extent.z; ++z) {
      for (std::uint64_t y = 0; y < coarse.extent.y; ++y) {
        for (std::uint64_t x = 0; x < coarse.extent.x; ++x) {
          double sum = 0.0;
          int n = 0;
          for (std::uint64_t dz = 0; dz < step.z; ++dz) {
            for (std::uint64_t dy = 0; dy < step.y; ++dy) {
              for (std::uint64_t dx = 0; dx < step.x; ++dx) {
                const glm::u64vec3 c{x * step.x + dx, y * step.y + dy, z * step.z + dz};
                if (c.x >= fine.extent.x || c.y >= fine.extent.y || c.z >= fine.extent.z) continue;
                const double v = fine.at(c.x, c.y, c.z);
                if (std::isnan(v)) continue;
                sum += v;
                ++n;
              }
            }
          }
          double r;
          if (t == VoxelType::f32) {
            r = n == 0 ? std::numeric_limits<double>::quiet_NaN() : double(float(sum / n));
          } else {
            // Round half up: the integer mean plus one half, floored.
            r = std::floor(sum / n + 0.5);
          }
          coarse.v[std::size_t((z * coarse.extent.y + y) * coarse.extent.x + x)] = r;
        }
      }
    }
  }
  return out;
}

double voxel_as_double(const std::byte* data, std::size_t i, VoxelType t) {
  switch (t) {
    case VoxelType::u8: return double(std::uint8_t(data[i]));
    case VoxelType::u16: {
      std::uint16_t v;
      std::memcpy(&v, data + 2 * i, 2);
      return double(v);
    }
    case VoxelType::f32: {
      float v;
      std::memcpy(&v, data + 4 * i, 4);
      return double(v);
    }
  }
  return 0.0;
}

}  // namespace resoct::test
