#include "support/function_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "resoct/volume/voxel_type.hpp"

namespace resoct::test {

namespace {
double to_type(double v, VoxelType t) {
  if (t == VoxelType::f32) return double(float(v));
  if (std::isnan(v)) return 0.0;
  const double hi = t == VoxelType::u8 ? 255.0 : 65535.0;
  return std::clamp(std::round(v), 0.0, hi);
}

void store(double v, VoxelType t, std::byte* dst) {
  switch (t) {
    case VoxelType::u8: {
      const auto x = std::uint8_t(v);
      std::memcpy(dst, &x, 1);
      break;
    }
    case VoxelType::u16: {
      const auto x = std::uint16_t(v);
      std::memcpy(dst, &x, 2);
      break;
    }
    case VoxelType::f32: {
      const auto x = float(v);
      std::memcpy(dst, &x, 4);
      break;
    }
  }
}
}  // namespace

FunctionSource::FunctionSource(VolumeDesc volume, BrickLayout layout, ValueFn value,
                               std::string name)
    : hierarchy_(std::move(volume), layout), name_(std::move(name)) {
  const VolumeDesc& v = hierarchy_.volume();
  levels_.resize(hierarchy_.level_count());
  for (std::uint32_t l = 0; l < hierarchy_.level_count(); ++l) {
    const LevelInfo& li = hierarchy_.level(l);
    for (std::uint32_t c = 0; c < v.channels; ++c) {
      std::vector<double> data(std::size_t(li.extent.x * li.extent.y * li.extent.z));
      std::size_t i = 0;
      for (std::uint64_t z = 0; z < li.extent.z; ++z) {
        for (std::uint64_t y = 0; y < li.extent.y; ++y) {
          for (std::uint64_t x = 0; x < li.extent.x; ++x, ++i) {
            if (l == 0) {
              data[i] = to_type(value(c, {x, y, z}), v.type);
              continue;
            }
            // Brute force from level 0: the average of the footprint's non-NaN voxels.
            const glm::u64vec3 lo(x << li.factor_log2.x, y << li.factor_log2.y,
                                  z << li.factor_log2.z);
            const glm::u64vec3 hi =
                glm::min(glm::u64vec3((x + 1) << li.factor_log2.x, (y + 1) << li.factor_log2.y,
                                      (z + 1) << li.factor_log2.z),
                         v.extent);
            double sum = 0.0;
            std::uint64_t n = 0;
            for (std::uint64_t zz = lo.z; zz < hi.z; ++zz) {
              for (std::uint64_t yy = lo.y; yy < hi.y; ++yy) {
                for (std::uint64_t xx = lo.x; xx < hi.x; ++xx) {
                  const double s = voxel(0, c, glm::i64vec3(xx, yy, zz));
                  if (std::isnan(s)) continue;
                  sum += s;
                  ++n;
                }
              }
            }
            data[i] = n == 0 ? std::nan("") : to_type(sum / double(n), v.type);
          }
        }
      }
      levels_[l].push_back(std::move(data));
    }
  }
}

double FunctionSource::voxel(std::uint32_t level, std::uint32_t channel, glm::i64vec3 p) const {
  const LevelInfo& li = hierarchy_.level(level);
  p = glm::clamp(p, glm::i64vec3(0), glm::i64vec3(li.extent) - std::int64_t(1));
  const std::size_t i =
      std::size_t((p.z * std::int64_t(li.extent.y) + p.y) * std::int64_t(li.extent.x) + p.x);
  return levels_[level][channel][i];
}

void FunctionSource::read_brick(BrickKey key, std::span<std::byte> out) const {
  check_brick_request(key, out);
  const VoxelType t = hierarchy_.volume().type;
  const std::size_t vs = voxel_size(t);
  const Box3 box = hierarchy_.padded_box(key.level(), key.brick());
  std::size_t i = 0;
  for (std::int64_t z = box.lo.z; z < box.hi.z; ++z) {
    for (std::int64_t y = box.lo.y; y < box.hi.y; ++y) {
      for (std::int64_t x = box.lo.x; x < box.hi.x; ++x, i += vs) {
        store(voxel(key.level(), key.channel(), {x, y, z}), t, out.data() + i);
      }
    }
  }
}

RegionMeta FunctionSource::region_meta(std::uint32_t channel, const Box3& level0_region) const {
  const VolumeDesc& v = hierarchy_.volume();
  const Box3 r = intersect(level0_region, Box3{glm::i64vec3(0), glm::i64vec3(v.extent)});
  const ValueRange range = v.range(channel);
  RegionMeta m;
  for (std::int64_t z = r.lo.z; z < r.hi.z; ++z) {
    for (std::int64_t y = r.lo.y; y < r.hi.y; ++y) {
      for (std::int64_t x = r.lo.x; x < r.hi.x; ++x) {
        const double s = voxel(0, channel, {x, y, z});
        if (std::isnan(s)) continue;
        m.min = std::min(m.min, s);
        m.max = std::max(m.max, s);
        m.occupancy |= occupancy_bit(s, range);
      }
    }
  }
  return m;
}

}  // namespace resoct::test
