#include "resoct/voxel_type.hpp"

#include <algorithm>
#include <cmath>

namespace resoct {

std::string_view to_string(VoxelType t) noexcept {
  switch (t) {
    case VoxelType::u8: return "u8";
    case VoxelType::u16: return "u16";
    case VoxelType::f32: return "f32";
  }
  return "unknown";
}

std::optional<VoxelType> parse_voxel_type(std::string_view s) noexcept {
  if (s == "u8" || s == "uint8") return VoxelType::u8;
  if (s == "u16" || s == "uint16") return VoxelType::u16;
  if (s == "f32" || s == "float32" || s == "float") return VoxelType::f32;
  return std::nullopt;
}

ValueRange default_range(VoxelType t) noexcept {
  switch (t) {
    case VoxelType::u8: return {0.0, 255.0};
    case VoxelType::u16: return {0.0, 65535.0};
    case VoxelType::f32: return {0.0, 1.0};
  }
  return {0.0, 1.0};
}

namespace {
// Bin of v, or -1 for NaN. Computed in double so that u16 and f32 values are not rounded into a
// neighbouring bin before clamping.
int occupancy_bin(double v, const ValueRange& r) noexcept {
  if (std::isnan(v)) return -1;
  const double t = (v - r.lo) / (r.hi - r.lo) * double(kOccupancyBins);
  if (!(t > 0.0)) return 0;  // also catches -inf
  if (t >= double(kOccupancyBins - 1)) return int(kOccupancyBins - 1);
  return int(t);
}
}  // namespace

std::uint32_t occupancy_bit(double v, const ValueRange& r) noexcept {
  const int b = occupancy_bin(v, r);
  return b < 0 ? 0u : (1u << b);
}

std::uint32_t occupancy_span(double lo, double hi, const ValueRange& r) noexcept {
  if (std::isnan(lo) || std::isnan(hi) || lo > hi) return 0u;
  const int a = occupancy_bin(lo, r);
  const int b = occupancy_bin(hi, r);
  const std::uint32_t upto_b = b >= 31 ? ~0u : ((1u << (b + 1)) - 1u);
  const std::uint32_t below_a = (1u << a) - 1u;
  return upto_b & ~below_a;
}

}  // namespace resoct
