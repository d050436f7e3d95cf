#pragma once
/// \file
/// What a volume is, independent of how it is bricked: extent, spacing, channels, voxel type.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/voxel_type.hpp"

namespace resoct {

/// Largest channel count a dataset may have (the brick key holds 8 bits of channel).
inline constexpr std::uint32_t kMaxChannels = 256;

struct VolumeDesc {
  glm::u64vec3 extent{1};          ///< level-0 voxels per axis, each >= 1
  glm::dvec3 spacing{1.0};         ///< physical size of one level-0 voxel per axis, each > 0
  std::uint32_t channels = 1;      ///< 1..kMaxChannels
  VoxelType type = VoxelType::u8;  ///< stored natively
  std::vector<ValueRange> ranges;  ///< one per channel; empty means default_range(type) for all

  /// Range of channel c (falls back to default_range(type) when `ranges` is empty).
  ValueRange range(std::uint32_t c) const;

  /// Level-0 voxels in one channel; throws Error(overflow) if it exceeds 64 bits.
  std::uint64_t voxel_count() const;

  /// Throws Error naming the offending field (`what` prefixes the message, e.g. a file name)
  /// when an extent is zero, the voxel or byte count overflows 64 bits, a spacing is not a
  /// positive finite number, the channel count is 0 or above kMaxChannels, or a range is empty.
  void validate(const std::string& what = "volume") const;

  friend bool operator==(const VolumeDesc&, const VolumeDesc&) = default;
};

/// Physical size of the whole volume: extent * spacing per axis.
glm::dvec3 physical_size(const VolumeDesc& v);

}  // namespace resoct
