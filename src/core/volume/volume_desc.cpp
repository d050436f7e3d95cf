#include "resoct/volume/volume_desc.hpp"

#include <cmath>
#include <limits>

#include "resoct/base/error.hpp"

namespace resoct {

ValueRange VolumeDesc::range(std::uint32_t c) const {
  if (ranges.empty()) return default_range(type);
  return ranges.at(c);
}

ValueRange VolumeDesc::data_range(std::uint32_t c) const {
  const ValueRange r = range(c);
  const double o = value_offset();
  return {r.lo - o, r.hi - o};
}

namespace {
bool mul_overflows(std::uint64_t a, std::uint64_t b, std::uint64_t& out) {
  return __builtin_mul_overflow(a, b, &out);
}
}  // namespace

std::uint64_t VolumeDesc::voxel_count() const {
  std::uint64_t n = 0;
  if (mul_overflows(extent.x, extent.y, n) || mul_overflows(n, extent.z, n)) {
    throw Error(ErrorCode::overflow, "volume extent " + std::to_string(extent.x) + "x" +
                                         std::to_string(extent.y) + "x" + std::to_string(extent.z) +
                                         ": voxel count overflows 64 bits");
  }
  return n;
}

void VolumeDesc::validate(const std::string& what) const {
  const char* axis[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    if (extent[i] == 0) {
      throw Error(ErrorCode::invalid_argument,
                  what + ": parameter 'extent." + axis[i] + "': must be at least 1");
    }
    if (!(std::isfinite(spacing[i]) && spacing[i] > 0.0)) {
      throw Error(ErrorCode::invalid_argument, what + ": parameter 'spacing." + axis[i] +
                                                   "': must be a positive finite number, got " +
                                                   std::to_string(spacing[i]));
    }
    if (!std::isfinite(origin[i])) {
      throw Error(ErrorCode::invalid_argument, what + ": parameter 'origin." + axis[i] +
                                                   "': must be a finite number, got " +
                                                   std::to_string(origin[i]));
    }
  }
  if (channels == 0 || channels > kMaxChannels) {
    throw Error(ErrorCode::invalid_argument, what + ": parameter 'channels': must be 1.." +
                                                 std::to_string(kMaxChannels) + ", got " +
                                                 std::to_string(channels));
  }
  if (type != VoxelType::u8 && type != VoxelType::u16 && type != VoxelType::f32) {
    throw Error(ErrorCode::invalid_argument, what + ": parameter 'type': unknown voxel type");
  }
  if (data_type && data_mapping(*data_type).stored != type) {
    throw Error(ErrorCode::invalid_argument,
                what + ": parameter 'data_type': " + std::string(to_string(*data_type)) +
                    " is kept as " + std::string(to_string(data_mapping(*data_type).stored)) +
                    ", not " + std::string(to_string(type)));
  }
  std::uint64_t n = 0;
  try {
    n = voxel_count();
  } catch (const Error& e) {
    throw Error(ErrorCode::overflow, what + ": " + e.what());
  }
  std::uint64_t bytes = 0;
  if (mul_overflows(n, std::uint64_t(channels) * voxel_size(type), bytes)) {
    throw Error(ErrorCode::overflow, what + ": byte count of all channels overflows 64 bits");
  }
  if (!ranges.empty() && ranges.size() != channels) {
    throw Error(ErrorCode::invalid_argument,
                what + ": parameter 'ranges': " + std::to_string(ranges.size()) + " ranges for " +
                    std::to_string(channels) + " channels");
  }
  for (std::size_t c = 0; c < ranges.size(); ++c) {
    const ValueRange& r = ranges[c];
    if (!(std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo < r.hi)) {
      throw Error(ErrorCode::invalid_argument, what + ": parameter 'ranges[" + std::to_string(c) +
                                                   "]': needs finite lo < hi, got [" +
                                                   std::to_string(r.lo) + ", " +
                                                   std::to_string(r.hi) + "]");
    }
  }
}

glm::dvec3 physical_size(const VolumeDesc& v) {
  return glm::dvec3(v.extent) * v.spacing;
}

}  // namespace resoct
