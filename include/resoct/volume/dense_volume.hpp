#pragma once
/// \file
/// All level-0 voxels of a volume in memory, backed by an owned vector or by memory someone else
/// owns (for example an mmap of a raw file), plus the clamped box copy that turns such buffers
/// into padded bricks.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include "resoct/volume/box.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

/// Level-0 voxels of every channel: channel-major, then z, y, x (x fastest), native type.
/// Immutable once built; copies share the storage. Thread-safe for concurrent reads.
class DenseVolume {
 public:
  DenseVolume() = default;

  /// Takes ownership of `bytes`. Throws Error(invalid_argument) naming "desc" or "data" when the
  /// description is invalid or the byte count is not channels * voxel_count * voxel_size.
  static DenseVolume from_bytes(VolumeDesc desc, std::vector<std::byte> bytes);

  /// Typed convenience: T must match desc.type (uint8_t, uint16_t or float).
  template <typename T>
  static DenseVolume from_values(VolumeDesc desc, const std::vector<T>& values);

  /// Wraps memory owned elsewhere; `keepalive` (e.g. the mapping) lives as long as any copy of
  /// the volume. Same checks as from_bytes, plus a null `data` is rejected.
  static DenseVolume from_pointer(VolumeDesc desc, const std::byte* data, std::size_t size,
                                  std::shared_ptr<const void> keepalive);

  const VolumeDesc& desc() const noexcept { return desc_; }
  std::span<const std::byte> bytes() const noexcept { return {data_.get(), size_}; }
  /// The voxels of one channel (throws Error(out_of_range) for a missing channel).
  std::span<const std::byte> channel_bytes(std::uint32_t channel) const;

  /// One voxel as double (any type). Throws Error(out_of_range) outside the volume.
  double value(std::uint32_t channel, const glm::u64vec3& p) const;
  /// One voxel in its native type; T must match the voxel type (else Error(invalid_argument)).
  template <typename T>
  T at(std::uint32_t channel, const glm::u64vec3& p) const;

 private:
  std::size_t offset(std::uint32_t channel, const glm::u64vec3& p) const;
  void check_type(std::size_t size) const;

  VolumeDesc desc_;
  std::shared_ptr<const std::byte> data_;
  std::size_t size_ = 0;
};

/// Writes the voxels of `dst_box` into `dst` (dense, x fastest) from `src`, a dense buffer
/// holding exactly the voxels of `src_box`; coordinates outside `src_box` are clamped to its
/// nearest voxel (clamp-to-edge halos). `src_box` must be non-empty and buffers sized to their
/// boxes (Error(invalid_argument) otherwise). Thread-safe (pure function).
void copy_box_clamped(std::span<const std::byte> src, const Box3& src_box, std::span<std::byte> dst,
                      const Box3& dst_box, std::size_t voxel_bytes);

template <typename T>
DenseVolume DenseVolume::from_values(VolumeDesc desc, const std::vector<T>& values) {
  std::vector<std::byte> bytes(values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
  DenseVolume v = from_bytes(std::move(desc), std::move(bytes));
  v.check_type(sizeof(T));
  return v;
}

template <typename T>
T DenseVolume::at(std::uint32_t channel, const glm::u64vec3& p) const {
  check_type(sizeof(T));
  T v;
  std::memcpy(&v, data_.get() + offset(channel, p), sizeof(T));
  return v;
}

}  // namespace resoct
