#pragma once
// Internal: the host-visible staging ring every host → device transfer goes through (bricks,
// page-table / octree deltas as (index, value) pairs, full arrays, per-frame tables).
//
// The backend records transfers into one command batch and waits for it before returning from
// render() (or earlier, when the ring fills up), so the ring is a linear allocator that restarts
// at 0 after each wait: no fences per region are needed. A transfer larger than the free space is
// split, the batch is flushed and the rest continues from the start of the ring.
#include <cstddef>
#include <cstdint>

#include <vulkan/vulkan.h>

#include "device_memory.hpp"

namespace resoct::vk::detail {

class StagingRing {
 public:
  /// Alignment of every region: 16 bytes covers the uint reads of the scatter shader and
  /// vkCmdCopyBuffer's optimal offsets.
  static constexpr VkDeviceSize kAlign = 16;

  StagingRing() = default;
  StagingRing(const StagingRing&) = delete;
  StagingRing& operator=(const StagingRing&) = delete;

  /// (Re)creates the ring of `bytes` (rounded up to kAlign). Throws Error(out_of_memory).
  void create(const Context& c, VkDeviceSize bytes);
  void destroy(const Context& c) noexcept;

  VkBuffer buffer() const noexcept { return buf_.buffer; }
  VkDeviceSize capacity() const noexcept { return buf_.size; }
  /// Bytes that a take() could still return before the next reset().
  VkDeviceSize free_bytes() const noexcept { return buf_.size - used_; }
  /// Takes min(want, free_bytes()) bytes at an aligned offset; the caller has checked that
  /// free_bytes() > 0. Returns the offset; `got` receives the size.
  VkDeviceSize take(VkDeviceSize want, VkDeviceSize& got) noexcept;
  std::byte* at(VkDeviceSize offset) const noexcept {
    return static_cast<std::byte*>(buf_.mapped) + offset;
  }
  /// Called once the device finished every transfer from the ring.
  void reset() noexcept { used_ = 0; }
  /// High-water mark since create() (statistics and tests).
  VkDeviceSize peak() const noexcept { return peak_; }

 private:
  Buffer buf_;
  VkDeviceSize used_ = 0;
  VkDeviceSize peak_ = 0;
};

}  // namespace resoct::vk::detail
