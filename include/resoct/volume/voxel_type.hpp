#pragma once
/// \file
/// Voxel types stored natively (never squashed to 8 bits) and per-channel value ranges.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
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

/// The type of the values in a user's file. The cache, the bricks and the kernel hold only the
/// three VoxelTypes; every other type is kept in one of them by data_mapping(): signed integers
/// exactly, with an offset (int16 CT values stay 2 bytes per voxel and exact), wider types as f32
/// (rounded: the only lossy mappings, reported by resoct-info). The first three codes equal
/// VoxelType's.
enum class DataType : std::uint8_t {
  u8 = 0,
  u16 = 1,
  f32 = 2,
  i8 = 3,
  i16 = 4,
  i32 = 5,
  u32 = 6,
  f64 = 7
};

/// Bytes of one value in the file: 1, 2, 4 or 8.
constexpr std::size_t data_size(DataType t) noexcept {
  switch (t) {
    case DataType::u8:
    case DataType::i8: return 1;
    case DataType::u16:
    case DataType::i16: return 2;
    case DataType::f64: return 8;
    default: return 4;
  }
}

/// How values of a DataType are kept: stored = value + offset, in `stored`.
struct DataMapping {
  VoxelType stored = VoxelType::u8;
  double offset = 0.0;  ///< 128 for i8, 32768 for i16, else 0
  /// Every value of the type survives the mapping. False for i32 and u32 (integers beyond
  /// 2^24 in magnitude are rounded to f32) and f64 (rounded to f32; out-of-range values become
  /// infinities).
  bool exact = true;
  friend bool operator==(const DataMapping&, const DataMapping&) = default;
};

/// u8, u16, f32: themselves; i8 -> u8 + 128; i16 -> u16 + 32768; i32, u32, f64 -> f32.
DataMapping data_mapping(DataType t) noexcept;
/// The raw value of one stored voxel of type `t` at `p` (unaligned; host byte order).
inline double voxel_value(const std::byte* p, VoxelType t) noexcept {
  switch (t) {
    case VoxelType::u8: return double(std::uint8_t(*p));
    case VoxelType::u16: {
      std::uint16_t v;
      std::memcpy(&v, p, sizeof v);
      return double(v);
    }
    case VoxelType::f32: {
      float v;
      std::memcpy(&v, p, sizeof v);
      return double(v);
    }
  }
  return 0.0;
}
/// The DataType whose values a VoxelType holds unmapped.
constexpr DataType data_type_of(VoxelType t) noexcept {
  return DataType(std::uint8_t(t));
}

/// "u8", "u16", "f32", "i8", "i16", "i32", "u32", "f64".
std::string_view to_string(DataType t) noexcept;
/// Parses the short names above and "uint8", "int8", "uint16", "int16", "int32", "uint32",
/// "float32", "float", "float64", "double"; empty on anything else.
std::optional<DataType> parse_data_type(std::string_view s) noexcept;
/// One line for users: "i16 (kept as u16, value + 32768: exact)" or "f64 (kept as f32: rounded)";
/// just the name for the three VoxelTypes.
std::string describe_mapping(DataType t);

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
