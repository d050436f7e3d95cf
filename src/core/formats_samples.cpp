#include "formats_samples.hpp"

#include <bit>
#include <cstring>

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

template <typename In, typename Out>
void convert(std::span<const std::byte> in, bool swap, bool scaled, double slope, double inter,
             std::span<std::byte> out) {
  const std::size_t n = in.size() / sizeof(In);
  for (std::size_t i = 0; i < n; ++i) {
    const In v = load<In>(in.data() + i * sizeof(In), swap);
    Out o;
    if constexpr (std::is_same_v<Out, float>) {
      o = scaled ? float(slope * double(v) + inter) : float(v);
    } else {
      o = Out(v);
    }
    std::memcpy(out.data() + i * sizeof(Out), &o, sizeof(Out));
  }
}

}  // namespace

std::size_t sample_bytes(SampleType t) noexcept {
  return t == SampleType::u8 ? 1u : t == SampleType::f32 ? 4u : 2u;
}

VoxelType voxel_type_for(SampleType t, bool scaled) noexcept {
  if (scaled || t == SampleType::i16 || t == SampleType::f32) return VoxelType::f32;
  return t == SampleType::u8 ? VoxelType::u8 : VoxelType::u16;
}

bool samples_are_voxels(SampleType t, Endian e, bool scaled) noexcept {
  if (scaled || t == SampleType::i16) return false;
  const bool host_little = std::endian::native == std::endian::little;
  return t == SampleType::u8 || (e == Endian::little) == host_little;
}

void convert_samples(std::span<const std::byte> in, SampleType t, Endian e, bool scaled,
                     double slope, double inter, std::span<std::byte> out) {
  const bool swap = (e == Endian::little) != (std::endian::native == std::endian::little);
  switch (voxel_type_for(t, scaled)) {
    case VoxelType::u8: convert<std::uint8_t, std::uint8_t>(in, false, false, 0, 0, out); return;
    case VoxelType::u16: convert<std::uint16_t, std::uint16_t>(in, swap, false, 0, 0, out); return;
    case VoxelType::f32: break;
  }
  switch (t) {
    case SampleType::u8: convert<std::uint8_t, float>(in, swap, scaled, slope, inter, out); break;
    case SampleType::i16: convert<std::int16_t, float>(in, swap, scaled, slope, inter, out); break;
    case SampleType::u16: convert<std::uint16_t, float>(in, swap, scaled, slope, inter, out); break;
    case SampleType::f32: convert<float, float>(in, swap, scaled, slope, inter, out); break;
  }
}

}  // namespace resoct::detail
