#pragma once
/// \file
/// Raw binary volume files: voxels with no self-describing header, whose extent, type, byte
/// order and channel count the caller supplies. The file is memory-mapped read-only, so opening
/// costs no copy when the file's byte order is the host's.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/dense_volume.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

/// Byte order of multi-byte voxels in a file.
enum class Endian : std::uint8_t { little, big };

/// "little", "big".
std::string_view to_string(Endian e) noexcept;
/// Parses "little"/"le" or "big"/"be"; empty on anything else.
std::optional<Endian> parse_endian(std::string_view s) noexcept;

/// How to interpret a raw file. Layout in the file after `offset` header bytes: channel-major
/// (all voxels of channel 0, then channel 1, ...), then z, y, x with x fastest.
struct RawVolumeOptions {
  glm::u64vec3 extent{0};          ///< voxels per axis (W, H, D), each >= 1
  VoxelType type = VoxelType::u8;  ///< u8, u16 or f32
  Endian endian = Endian::little;  ///< byte order of u16 / f32 voxels (ignored for u8)
  glm::dvec3 spacing{1.0};         ///< physical voxel size, each a positive finite number
  glm::dvec3 origin{0.0};          ///< VolumeDesc::origin: low corner of voxel 0, each finite
  std::uint32_t channels = 1;      ///< 1..kMaxChannels
  std::uint64_t offset = 0;        ///< header bytes skipped before the first voxel
  std::vector<ValueRange> ranges;  ///< one per channel, or empty for default_range(type)
  /// The file's value type, any DataType; when set, `type` is ignored. Values of a type that is
  /// not a VoxelType (i8, i16, i32, u32, f64) are kept as data_mapping(*data_type) says
  /// (voxel_type.hpp) in a copy, and `ranges` are in the file's units (an int16 CT window
  /// [-1000, 2000]).
  std::optional<DataType> data_type;
};

/// Opens a raw volume file as a DenseVolume.
///
/// When the file's byte order is the host's and `offset` keeps voxels aligned to their size, the
/// volume wraps a read-only mmap of the file (unmapped when the last copy of the volume goes
/// away); otherwise the voxels are read into an owned buffer and byte-swapped as needed. Bytes
/// after the last voxel are ignored. The file must not be truncated while a mapping is alive.
///
/// Throws Error(invalid_argument | overflow) naming the parameter ("extent.x", "channels",
/// "spacing.y", "offset", ...) when the options are invalid or the byte count overflows 64 bits;
/// Error(io) naming `path` when it cannot be opened or mapped; Error(truncated) naming `path`,
/// the expected and the actual size when the file is shorter than offset + all voxels.
/// Thread-safety: a pure function; the result is immutable and safe to read from many threads.
DenseVolume open_raw_volume(const std::string& path, const RawVolumeOptions& options);

}  // namespace resoct
