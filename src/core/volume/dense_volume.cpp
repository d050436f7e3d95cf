#include "resoct/volume/dense_volume.hpp"

#include <algorithm>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {
std::uint64_t expected_bytes(const VolumeDesc& desc) {
  desc.validate("desc");
  return desc.voxel_count() * desc.channels * voxel_size(desc.type);
}

void check_data_size(const VolumeDesc& desc, std::size_t size) {
  const std::uint64_t want = expected_bytes(desc);
  if (size != want) {
    throw invalid_parameter(
        "data", std::to_string(size) + " bytes, expected " + std::to_string(want) + " for " +
                    std::to_string(desc.channels) + " channel(s) of " +
                    std::to_string(desc.extent.x) + "x" + std::to_string(desc.extent.y) + "x" +
                    std::to_string(desc.extent.z) + " " + std::string(to_string(desc.type)));
  }
}
}  // namespace

DenseVolume DenseVolume::from_bytes(VolumeDesc desc, std::vector<std::byte> bytes) {
  check_data_size(desc, bytes.size());
  auto owner = std::make_shared<std::vector<std::byte>>(std::move(bytes));
  DenseVolume v;
  v.desc_ = std::move(desc);
  v.size_ = owner->size();
  // Aliasing constructor: the vector stays alive as long as the byte pointer does.
  v.data_ = std::shared_ptr<const std::byte>(owner, owner->data());
  return v;
}

DenseVolume DenseVolume::from_pointer(VolumeDesc desc, const std::byte* data, std::size_t size,
                                      std::shared_ptr<const void> keepalive) {
  if (data == nullptr) throw invalid_parameter("data", "null pointer");
  check_data_size(desc, size);
  DenseVolume v;
  v.desc_ = std::move(desc);
  v.size_ = size;
  v.data_ = std::shared_ptr<const std::byte>(std::move(keepalive), data);
  return v;
}

std::span<const std::byte> DenseVolume::channel_bytes(std::uint32_t channel) const {
  if (channel >= desc_.channels) {
    throw Error(ErrorCode::out_of_range, "parameter 'channel': " + std::to_string(channel) +
                                             " of " + std::to_string(desc_.channels));
  }
  const std::size_t n = size_ / desc_.channels;
  return bytes().subspan(std::size_t(channel) * n, n);
}

std::size_t DenseVolume::offset(std::uint32_t channel, const glm::u64vec3& p) const {
  const glm::u64vec3& e = desc_.extent;
  if (channel >= desc_.channels || p.x >= e.x || p.y >= e.y || p.z >= e.z) {
    throw Error(ErrorCode::out_of_range, "parameter 'p': voxel (" + std::to_string(p.x) + "," +
                                             std::to_string(p.y) + "," + std::to_string(p.z) +
                                             ") channel " + std::to_string(channel) +
                                             " outside the volume");
  }
  return std::size_t((((std::uint64_t(channel) * e.z + p.z) * e.y + p.y) * e.x + p.x) *
                     voxel_size(desc_.type));
}

void DenseVolume::check_type(std::size_t size) const {
  if (size != voxel_size(desc_.type)) {
    throw invalid_parameter(
        "T", "accessor type does not match voxel type " + std::string(to_string(desc_.type)));
  }
}

double DenseVolume::value(std::uint32_t channel, const glm::u64vec3& p) const {
  switch (desc_.type) {
    case VoxelType::u8: return double(at<std::uint8_t>(channel, p));
    case VoxelType::u16: return double(at<std::uint16_t>(channel, p));
    case VoxelType::f32: return double(at<float>(channel, p));
  }
  return 0.0;
}

void copy_box_clamped(std::span<const std::byte> src, const Box3& src_box, std::span<std::byte> dst,
                      const Box3& dst_box, std::size_t voxel_bytes) {
  if (src_box.empty()) throw invalid_parameter("src_box", "must not be empty");
  if (src.size() != std::uint64_t(src_box.volume()) * voxel_bytes ||
      dst.size() != std::uint64_t(dst_box.volume()) * voxel_bytes) {
    throw invalid_parameter("src/dst", "buffer sizes do not match their boxes");
  }
  if (dst_box.empty()) return;
  const glm::i64vec3 ss = src_box.size();
  auto clamp = [](std::int64_t v, std::int64_t lo, std::int64_t hi) {
    return std::min(std::max(v, lo), hi - 1) - lo;
  };
  // Split each row into the left clamp run, the copied middle and the right clamp run.
  const std::int64_t mid_lo = std::max(dst_box.lo.x, src_box.lo.x);
  const std::int64_t mid_hi = std::min(dst_box.hi.x, src_box.hi.x);
  const std::size_t vb = voxel_bytes;
  std::byte* d = dst.data();
  for (std::int64_t z = dst_box.lo.z; z < dst_box.hi.z; ++z) {
    const std::int64_t sz = clamp(z, src_box.lo.z, src_box.hi.z);
    for (std::int64_t y = dst_box.lo.y; y < dst_box.hi.y; ++y) {
      const std::int64_t sy = clamp(y, src_box.lo.y, src_box.hi.y);
      const std::byte* row = src.data() + std::size_t((sz * ss.y + sy) * ss.x) * vb;
      std::int64_t x = dst_box.lo.x;
      for (; x < std::min(mid_lo, dst_box.hi.x); ++x, d += vb) std::memcpy(d, row, vb);
      if (mid_hi > mid_lo) {
        const std::size_t n = std::size_t(mid_hi - mid_lo) * vb;
        std::memcpy(d, row + std::size_t(mid_lo - src_box.lo.x) * vb, n);
        d += n;
        x = mid_hi;
      }
      const std::byte* last = row + std::size_t(ss.x - 1) * vb;
      for (x = std::max(x, src_box.hi.x); x < dst_box.hi.x; ++x, d += vb) {
        std::memcpy(d, last, vb);
      }
    }
  }
}

}  // namespace resoct
