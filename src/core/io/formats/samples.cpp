#include "io/formats/samples.hpp"

#include <bit>
#include <cstring>
#include <limits>
#include <type_traits>

namespace resoct::detail {

namespace {

template <typename T>
T load(const std::byte* p, bool swap) {
  std::byte tmp[sizeof(T)];
  std::memcpy(tmp, p, sizeof(T));
  if (swap) {
    for (std::size_t a = 0, z = sizeof(T) - 1; a < z; ++a, --z) std::swap(tmp[a], tmp[z]);
  }
  T v;
  std::memcpy(&v, tmp, sizeof(T));
  return v;
}

/// Out is float for scaled and wide values; otherwise the unsigned type of In's width, reached
/// by adding the mapping's offset (exact: -32768..32767 + 32768 is 0..65535).
template <typename In, typename Out>
void convert(std::span<const std::byte> in, bool swap, bool scaled, double slope, double inter,
             std::span<std::byte> out) {
  const std::size_t n = in.size() / sizeof(In);
  for (std::size_t i = 0; i < n; ++i) {
    const In v = load<In>(in.data() + i * sizeof(In), swap);
    Out o;
    if constexpr (std::is_same_v<Out, float>) {
      o = scaled ? float(slope * double(v) + inter) : float(v);
    } else if constexpr (std::is_signed_v<In>) {
      o = Out(std::int32_t(v) - std::int32_t(std::numeric_limits<In>::min()));
    } else {
      o = Out(v);
    }
    std::memcpy(out.data() + i * sizeof(Out), &o, sizeof(Out));
  }
}

}  // namespace

VoxelType voxel_type_for(DataType t, bool scaled) noexcept {
  return scaled ? VoxelType::f32 : data_mapping(t).stored;
}

bool samples_are_voxels(DataType t, Endian e, bool scaled) noexcept {
  if (scaled || data_type_of(data_mapping(t).stored) != t) return false;
  const bool host_little = std::endian::native == std::endian::little;
  return t == DataType::u8 || (e == Endian::little) == host_little;
}

void convert_samples(std::span<const std::byte> in, DataType t, Endian e, bool scaled, double slope,
                     double inter, std::span<std::byte> out) {
  const bool swap = (e == Endian::little) != (std::endian::native == std::endian::little);
  if (!scaled) {
    switch (t) {
      case DataType::u8: convert<std::uint8_t, std::uint8_t>(in, false, false, 0, 0, out); return;
      case DataType::i8: convert<std::int8_t, std::uint8_t>(in, false, false, 0, 0, out); return;
      case DataType::u16: convert<std::uint16_t, std::uint16_t>(in, swap, false, 0, 0, out); return;
      case DataType::i16: convert<std::int16_t, std::uint16_t>(in, swap, false, 0, 0, out); return;
      default: break;
    }
  }
  switch (t) {
    case DataType::u8: convert<std::uint8_t, float>(in, false, scaled, slope, inter, out); break;
    case DataType::i8: convert<std::int8_t, float>(in, false, scaled, slope, inter, out); break;
    case DataType::u16: convert<std::uint16_t, float>(in, swap, scaled, slope, inter, out); break;
    case DataType::i16: convert<std::int16_t, float>(in, swap, scaled, slope, inter, out); break;
    case DataType::i32: convert<std::int32_t, float>(in, swap, scaled, slope, inter, out); break;
    case DataType::u32: convert<std::uint32_t, float>(in, swap, scaled, slope, inter, out); break;
    case DataType::f32: convert<float, float>(in, swap, scaled, slope, inter, out); break;
    case DataType::f64: convert<double, float>(in, swap, scaled, slope, inter, out); break;
  }
}

}  // namespace resoct::detail
