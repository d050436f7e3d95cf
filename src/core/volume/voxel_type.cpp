#include "resoct/volume/voxel_type.hpp"

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

DataMapping data_mapping(DataType t) noexcept {
  switch (t) {
    case DataType::u8: return {VoxelType::u8, 0.0, true};
    case DataType::u16: return {VoxelType::u16, 0.0, true};
    case DataType::f32: return {VoxelType::f32, 0.0, true};
    case DataType::i8: return {VoxelType::u8, 128.0, true};
    case DataType::i16: return {VoxelType::u16, 32768.0, true};
    case DataType::i32:
    case DataType::u32:
    case DataType::f64: return {VoxelType::f32, 0.0, false};
  }
  return {};
}

std::string_view to_string(DataType t) noexcept {
  switch (t) {
    case DataType::u8: return "u8";
    case DataType::u16: return "u16";
    case DataType::f32: return "f32";
    case DataType::i8: return "i8";
    case DataType::i16: return "i16";
    case DataType::i32: return "i32";
    case DataType::u32: return "u32";
    case DataType::f64: return "f64";
  }
  return "unknown";
}

std::optional<DataType> parse_data_type(std::string_view s) noexcept {
  if (auto v = parse_voxel_type(s)) return data_type_of(*v);
  if (s == "i8" || s == "int8") return DataType::i8;
  if (s == "i16" || s == "int16") return DataType::i16;
  if (s == "i32" || s == "int32") return DataType::i32;
  if (s == "u32" || s == "uint32") return DataType::u32;
  if (s == "f64" || s == "float64" || s == "double") return DataType::f64;
  return std::nullopt;
}

std::string describe_mapping(DataType t) {
  const DataMapping m = data_mapping(t);
  std::string out(to_string(t));
  if (data_type_of(m.stored) == t) return out;
  out += " (kept as ";
  out += to_string(m.stored);
  if (m.offset != 0.0) out += ", value + " + std::to_string(std::int64_t(m.offset));
  out += m.exact ? ": exact)" : ": rounded)";
  return out;
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
