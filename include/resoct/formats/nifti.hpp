#pragma once
/// \file
/// NIfTI-1 single-file volumes (.nii, and .nii.gz through zlib) as brick sources.
///
/// Voxel mapping (the volume is served in voxel index order i, j, k = x, y, z; no reorientation):
/// - scl_slope and scl_inter that are NaN or infinite read as 0 (as in niftilib), and a
///   scl_slope of 0 means no scaling, scl_inter ignored (the NIfTI-1 rule);
/// - without scaling (scl_slope 0, or 1 with scl_inter 0) values keep their type through
///   data_mapping() (voxel_type.hpp): u8, u16, f32 as they are, int8 / int16 exactly as u8 / u16
///   plus an offset (VolumeDesc::data_type says so), int32, uint32 and float64 as f32 (rounded);
/// - any scaling (scl_slope not 0 and either not 1 or scl_inter not 0) gives
///   f32 = slope * v + inter.
/// Spacing: the column lengths of the sform matrix when sform_code > 0, else |pixdim[1..3]|
/// (qform and the fallback method share pixdim); a zero or non-finite spacing becomes 1.
/// A 4-D file's volumes (dim[4] up to 256) become channels; dims 5..7 must be 1.
/// Each channel's value range is the finite min/max of its data.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "resoct/brick_source.hpp"
#include "resoct/raw_volume.hpp"
#include "resoct/voxel_type.hpp"

namespace resoct {

/// The fields of a NIfTI-1 header that resoct uses.
struct NiftiHeader {
  Endian endian = Endian::little;     ///< from sizeof_hdr (348 in the file's byte order)
  std::array<std::int64_t, 8> dim{};  ///< dim[0] = rank 1..7, dim[1..rank] >= 1
  /// From the datatype code: 2 u8, 256 i8, 4 i16, 512 u16, 8 i32, 768 u32, 16 f32, 64 f64.
  DataType datatype = DataType::u8;
  std::array<float, 8> pixdim{};
  std::uint64_t vox_offset = 352;  ///< byte offset of the first voxel (>= 348)
  float scl_slope = 0.0f;          ///< 0 when the file's value is NaN or infinite
  float scl_inter = 0.0f;          ///< 0 when the file's value is NaN or infinite
  std::int16_t qform_code = 0;
  std::int16_t sform_code = 0;
  std::array<std::array<float, 4>, 3> srow{};  ///< srow_x, srow_y, srow_z

  glm::u64vec3 extent() const noexcept;
  /// dim[4] when rank >= 4, else 1.
  std::uint32_t volumes() const noexcept;
  /// Physical voxel size per axis (rule in the file comment).
  glm::dvec3 spacing() const noexcept;
  /// True when scl_slope / scl_inter change values.
  bool scaled() const noexcept;
  /// Stored bytes per voxel.
  std::size_t stored_voxel_bytes() const noexcept;
  /// Stored voxel bytes of the whole image: extent * volumes * stored_voxel_bytes.
  std::uint64_t data_bytes() const;
};

/// Parses the first 348 bytes of a NIfTI-1 file (the caller decompresses .nii.gz first).
/// Throws Error(truncated) naming `location` when fewer than 348 bytes are given,
/// Error(bad_magic) when sizeof_hdr is not 348 in either byte order or the magic is not "n+1"
/// (the two-file "ni1" form is reported as unsupported), Error(corrupt) naming the field and
/// its offset for a rank outside 1..7, a non-positive dimension or a vox_offset below 348,
/// Error(unsupported) for a datatype other than those of NiftiHeader::datatype, bitpix disagreeing
/// with it, or dims 5..7 above 1, Error(overflow) when the data size overflows. Thread-safety:
/// pure.
NiftiHeader parse_nifti_header(std::span<const std::byte> bytes, std::string_view location);

/// Opens a .nii or .nii.gz file (gzip recognised by its magic bytes) as a brick source whose
/// coarser levels are built on demand (see pyramid_source.hpp). The decoded voxels are held in
/// memory (an uncompressed .nii of the host byte order and no conversion is memory-mapped).
/// Throws what parse_nifti_header throws, Error(io) when the file cannot be read,
/// Error(truncated) naming the file when it ends before the data. Thread-safety: the source is.
std::unique_ptr<BrickSource> open_nifti(const std::string& path, const BrickLayout& layout = {});

}  // namespace resoct
