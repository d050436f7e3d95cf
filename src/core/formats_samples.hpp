#pragma once
// Stored samples of single-resolution formats (NIfTI, NRRD) to resoct voxels (internal).

#include <cstddef>
#include <cstdint>
#include <span>

#include "resoct/raw_volume.hpp"
#include "resoct/voxel_type.hpp"

namespace resoct::detail {

/// Sample types these formats store.
enum class SampleType : std::uint8_t { u8, i16, u16, f32 };

std::size_t sample_bytes(SampleType t) noexcept;

/// The voxel type a stored type becomes: u8 and u16 stay unless `scaled`; i16 and every scaled
/// type become f32 (no signed type in resoct; f32 holds every i16 and u16 exactly).
VoxelType voxel_type_for(SampleType t, bool scaled) noexcept;

/// True when the stored bytes are already resoct voxels (no conversion, host byte order).
bool samples_are_voxels(SampleType t, Endian e, bool scaled) noexcept;

/// Converts in.size() / sample_bytes(t) samples of byte order `e` into voxels of
/// voxel_type_for(t, scaled) in `out` (sized accordingly): v' = slope * v + inter when scaled.
void convert_samples(std::span<const std::byte> in, SampleType t, Endian e, bool scaled,
                     double slope, double inter, std::span<std::byte> out);

}  // namespace resoct::detail
