#pragma once
/// \file
/// NIfTI-1 and NIfTI-2 volumes as brick sources: single files (.nii, .nii.gz), two-file pairs
/// (.hdr + .img, either gzipped) and plain Analyze 7.5 pairs. docs/formats.md ("NIfTI") has the
/// user-facing rules; in short:
///
/// Values (scl_slope / scl_inter as niftilib reads them):
/// - scl_slope and scl_inter that are NaN or infinite read as 0, and a scl_slope of 0 means no
///   scaling, scl_inter ignored (the NIfTI-1 rule);
/// - without scaling (scl_slope 0, or 1 with scl_inter 0) values keep their type through
///   data_mapping() (voxel_type.hpp): u8, u16, f32 as they are, int8 / int16 exactly as u8 / u16
///   plus an offset (VolumeDesc::data_type says so), int32, uint32 and float64 as f32 (rounded);
/// - any scaling gives f32 = slope * v + inter. Analyze 7.5 headers are never scaled.
/// Dimensions: dim[1..3] are space, dim[4] is time (one timepoint is served, chosen by
/// NiftiOptions::timepoint), dim[5] holds components (vector / tensor intents) that become
/// channels (at most 256); dim[6..7] must be 1.
/// Placement: the voxel-to-world map is the sform when sform_code > 0, else the qform when
/// qform_code > 0, else pixdim alone (origin 0). Voxels are reordered on read so that served
/// +x, +y, +z run along world +R, +A, +S (the nearest axis permutation and flips); spacing is
/// the length of each index axis's world step, VolumeDesc::origin the low corner of the served
/// voxel 0. Rotations beyond permutations and flips (oblique acquisitions) and shears are not
/// applied. Analyze 7.5 is served in index order with pixdim spacing and origin 0.
/// Each channel's value range is the finite min/max of its data.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/sources/brick_source.hpp"
#include "resoct/io/formats/raw_volume.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// Which file layout a header announces by its magic.
enum class NiftiForm : std::uint8_t {
  single,   ///< "n+1" / "n+2": header and data in one .nii
  pair,     ///< "ni1" / "ni2": header in .hdr, data in .img beside it
  analyze,  ///< no NIfTI magic in a 348-byte header: Analyze 7.5 .hdr / .img
};

/// The fields of a NIfTI-1 / NIfTI-2 header that resoct uses, widened to the NIfTI-2 types.
struct NiftiHeader {
  int version = 1;  ///< 1 (348-byte header, also Analyze) or 2 (540 bytes)
  NiftiForm form = NiftiForm::single;
  Endian endian = Endian::little;     ///< from sizeof_hdr (348 / 540 in the file's byte order)
  std::array<std::int64_t, 8> dim{};  ///< dim[0] = rank 1..7, dim[1..rank] >= 1
  /// From the datatype code: 2 u8, 256 i8, 4 i16, 512 u16, 8 i32, 768 u32, 16 f32, 64 f64.
  DataType datatype = DataType::u8;
  std::array<double, 8> pixdim{};  ///< pixdim[0] is qfac (-1 flips k in the qform)
  /// Byte offset of the first voxel: in the .nii (>= the header size), or in the .img of a pair.
  std::uint64_t vox_offset = 352;
  double scl_slope = 0.0;           ///< 0 when the file's value is NaN or infinite, and for Analyze
  double scl_inter = 0.0;           ///< 0 when the file's value is NaN or infinite, and for Analyze
  std::int32_t qform_code = 0;      ///< 0 for Analyze
  std::int32_t sform_code = 0;      ///< 0 for Analyze
  std::array<double, 3> quatern{};  ///< quatern_b, quatern_c, quatern_d
  std::array<double, 3> qoffset{};  ///< qoffset_x, qoffset_y, qoffset_z
  std::array<std::array<double, 4>, 3> srow{};  ///< srow_x, srow_y, srow_z

  /// 348 or 540: the bytes parse_nifti_header reads.
  std::size_t header_bytes() const noexcept { return version == 2 ? 540 : 348; }
  glm::u64vec3 extent() const noexcept;
  /// dim[4] when rank >= 4, else 1: the time axis (fMRI volumes, diffusion directions).
  std::uint64_t timepoints() const noexcept;
  /// dim[5] when rank >= 5, else 1: components per voxel, served as channels (<= 256).
  std::uint32_t components() const noexcept;
  /// Voxel index (i, j, k) to world (x, y, z) of the voxel's centre, as rows [R | t]: world =
  /// R * index + t (the sform, else the qform, else diag(pixdim)). Zero, negative or non-finite
  /// pixdim read as 1 in the qform and fallback maps (as niftilib does for zero).
  std::array<std::array<double, 4>, 3> voxel_to_world() const noexcept;
  /// Physical voxel size per index axis: the lengths of voxel_to_world()'s columns (a zero or
  /// non-finite length becomes 1).
  glm::dvec3 spacing() const noexcept;
  /// True when scl_slope / scl_inter change values.
  bool scaled() const noexcept;
  /// Stored bytes per voxel.
  std::size_t stored_voxel_bytes() const noexcept;
  /// Stored bytes of one 3-D volume (one timepoint of one component).
  std::uint64_t volume_bytes() const;
  /// Stored voxel bytes of the whole image: volume_bytes * timepoints * components.
  std::uint64_t data_bytes() const;
};

/// Parses a NIfTI-1 (first 348 bytes), NIfTI-2 (first 540 bytes) or Analyze 7.5 header (the
/// caller decompresses .nii.gz / .hdr.gz first; giving 540 bytes or the whole file is fine).
/// Throws Error(truncated) naming `location` when fewer bytes than the header's size are given,
/// Error(bad_magic) when sizeof_hdr is neither 348 nor 540 in either byte order, or a 540-byte
/// header lacks the NIfTI-2 magic; Error(corrupt) naming the field and its offset for a rank
/// outside 1..7, a non-positive dimension, a negative or fractional vox_offset or one inside the
/// header of a single file, bitpix disagreeing with the datatype; Error(unsupported) for another
/// datatype, dim[5] above 256 or dims 6..7 above 1; Error(overflow) when the data size overflows.
/// A 348-byte header without NIfTI magic parses as Analyze 7.5 (form analyze). Thread-safety:
/// pure.
NiftiHeader parse_nifti_header(std::span<const std::byte> bytes, std::string_view location);

/// Reads and parses the header of a NIfTI / Analyze file or pair (`path` as open_nifti takes
/// it), e.g. to learn timepoints() before choosing one. Throws what open_nifti throws for it.
NiftiHeader read_nifti_header(const std::string& path);

/// Choices made when a NIfTI file is opened.
struct NiftiOptions {
  /// Which timepoint (index along dim[4]) is served, 0-based. Out of range:
  /// Error(invalid_argument) naming parameter 'timepoint' and the file's count.
  std::uint64_t timepoint = 0;
  /// Value range of each channel in stored units (VolumeDesc::ranges), one per channel; empty:
  /// each channel's finite data range of the timepoint opened. The series' other timepoints
  /// (BrickSource::open_timepoint) are opened with this source's ranges, so that one transfer
  /// function maps every timepoint alike.
  std::vector<ValueRange> ranges;
};

/// Opens a NIfTI / Analyze image as a brick source whose coarser levels are built on demand (see
/// pyramid_source.hpp). `path` is a .nii / .nii.gz, or either file of a pair: x.hdr[.gz] finds
/// its data in x.img or x.img.gz beside it, x.img[.gz] its header in x.hdr or x.hdr.gz (gzip is
/// recognised by its magic bytes). The data file must lie in the header's directory (symbolic
/// links leading out are refused, docs/formats.md "Files a file may name"). The decoded voxels
/// of the chosen timepoint are held in memory (an uncompressed file of the host byte order, no
/// conversion and no reordering is memory-mapped). Throws what parse_nifti_header throws,
/// Error(io) naming a file that cannot be read or a missing data / header file,
/// Error(truncated) naming the file when it ends before the data, Error(invalid_argument) for
/// a timepoint out of range or a single-file header in a .hdr (and a pair header in a .nii).
/// Thread-safety: the source is.
std::unique_ptr<BrickSource> open_nifti(const std::string& path, const BrickLayout& layout = {},
                                        const NiftiOptions& options = {});

}  // namespace resoct
