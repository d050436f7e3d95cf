#pragma once
/// \file
/// What a volume is, independent of how it is bricked: extent, spacing, physical origin, channels,
/// voxel type (and the file's own value type when it is kept mapped).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// Largest channel count a dataset may have (the brick key holds 8 bits of channel).
inline constexpr std::uint32_t kMaxChannels = 256;

struct VolumeDesc {
  glm::u64vec3 extent{1};   ///< level-0 voxels per axis, each >= 1
  glm::dvec3 spacing{1.0};  ///< physical size of one level-0 voxel per axis, each > 0
  /// Physical position of the low corner of voxel (0, 0, 0), in the units of `spacing` and in
  /// the file's world frame (NIfTI RAS+, NRRD converted to RAS+, OME-Zarr's own axes): voxel
  /// (i, j, k) covers origin + (i, j, k) * spacing .. origin + (i + 1, j + 1, k + 1) * spacing.
  /// The formats place voxel centres, so a reader sets origin = centre of voxel 0 - spacing / 2
  /// (docs/formats.md, "Physical placement"). Each component finite; not persisted in brick
  /// stores (they read back 0).
  glm::dvec3 origin{0.0};
  std::uint32_t channels = 1;      ///< 1..kMaxChannels
  VoxelType type = VoxelType::u8;  ///< stored natively
  std::vector<ValueRange> ranges;  ///< one per channel; empty means default_range(type) for all
  /// The type of the values in the file when it is not `type` itself (int16 CT kept as u16,
  /// float64 kept as f32: data_mapping()). Voxels, `ranges` and everything downstream are in
  /// stored units (value + data_mapping(data_type).offset); data_range() gives the file's units.
  std::optional<DataType> data_type;

  /// Range of channel c (falls back to default_range(type) when `ranges` is empty), in stored
  /// units.
  ValueRange range(std::uint32_t c) const;
  /// The file's value type: data_type, or `type`'s own.
  DataType file_type() const noexcept { return data_type.value_or(data_type_of(type)); }
  /// Stored value minus file value: 32768 for i16, 128 for i8, else 0.
  double value_offset() const noexcept { return data_mapping(file_type()).offset; }
  /// range(c) in the file's units (an int16 CT channel reads [-1024, 3071], not [31744, 35839]).
  ValueRange data_range(std::uint32_t c) const;

  /// Level-0 voxels in one channel; throws Error(overflow) if it exceeds 64 bits.
  std::uint64_t voxel_count() const;

  /// Throws Error naming the offending field (`what` prefixes the message, e.g. a file name)
  /// when an extent is zero, the voxel or byte count overflows 64 bits, a spacing is not a
  /// positive finite number, an origin component is not finite, the channel count is 0 or above
  /// kMaxChannels, or a range is empty.
  void validate(const std::string& what = "volume") const;

  friend bool operator==(const VolumeDesc&, const VolumeDesc&) = default;
};

/// Physical size of the whole volume: extent * spacing per axis.
glm::dvec3 physical_size(const VolumeDesc& v);

}  // namespace resoct
