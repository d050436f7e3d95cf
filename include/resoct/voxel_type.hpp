#pragma once
/// \file
/// Voxel types stored natively (never squashed to 8 bits) and per-channel value ranges.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace resoct {

enum class VoxelType : std::uint8_t { u8 = 0, u16 = 1, f32 = 2 };

constexpr std::size_t voxel_size(VoxelType t) noexcept {
  return t == VoxelType::u8 ? 1u : t == VoxelType::u16 ? 2u : 4u;
}

/// "u8", "u16", "f32".
std::string_view to_string(VoxelType t) noexcept;
/// Parses "u8", "u16", "f32" (also "uint8", "uint16", "float32"); empty on anything else.
std::optional<VoxelType> parse_voxel_type(std::string_view s) noexcept;

/// Value range [lo, hi] of one channel's raw voxel values. It maps voxel values linearly to [0, 1]
/// for transfer functions and defines the bins of the occupancy bitmask.
struct ValueRange {
  double lo = 0.0;
  double hi = 1.0;
  friend bool operator==(const ValueRange&, const ValueRange&) = default;
};

/// Full representable range of an integer type; [0, 1] for f32.
ValueRange default_range(VoxelType t) noexcept;

/// Number of bins of the coarse value-occupancy bitmask (one bit per bin).
inline constexpr std::uint32_t kOccupancyBins = 32;

/// The occupancy bit of value v over range r: bin floor((v - lo) / (hi - lo) * 32), clamped to
/// [0, 31] so that values outside the range still mark the outermost bins. NaN marks no bin.
std::uint32_t occupancy_bit(double v, const ValueRange& r) noexcept;

/// All bins that intersect [lo, hi]: a conservative occupancy mask when only min and max are known.
std::uint32_t occupancy_span(double lo, double hi, const ValueRange& r) noexcept;

}  // namespace resoct
