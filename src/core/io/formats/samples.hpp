#pragma once
// Stored samples of the single-resolution formats (NIfTI, NRRD, TIFF, raw) and of zarr chunks to
// resoct voxels (internal): the one place where data_mapping() is applied to file values.

#include <cstddef>
#include <cstdint>
#include <span>

#include "resoct/io/formats/raw_volume.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct::detail {

/// The voxel type file values of type `t` become: data_mapping(t).stored, or f32 when `scaled`
/// (NIfTI scl_slope / scl_inter other than the identity).
VoxelType voxel_type_for(DataType t, bool scaled) noexcept;

/// True when the stored bytes are already resoct voxels (no conversion, host byte order).
bool samples_are_voxels(DataType t, Endian e, bool scaled) noexcept;

/// Converts in.size() / data_size(t) values of byte order `e` into voxels of
/// voxel_type_for(t, scaled) in `out` (sized accordingly): v' = slope * v + inter when scaled,
/// else v + data_mapping(t).offset.
void convert_samples(std::span<const std::byte> in, DataType t, Endian e, bool scaled, double slope,
                     double inter, std::span<std::byte> out);

}  // namespace resoct::detail
