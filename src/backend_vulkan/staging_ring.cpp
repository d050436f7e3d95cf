#include "staging_ring.hpp"

#include <algorithm>

namespace resoct::vk::detail {

void StagingRing::create(const Context& c, VkDeviceSize bytes) {
  destroy(c);
  const VkDeviceSize size = (std::max<VkDeviceSize>(bytes, kAlign) + kAlign - 1) / kAlign * kAlign;
  // Storage use: the scatter shader reads its (index, value) pairs straight from the ring.
  buf_ =
      create_buffer(c, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                    MemoryUse::upload, "staging ring");
}

void StagingRing::destroy(const Context& c) noexcept {
  destroy_buffer(c, buf_);
  used_ = 0;
  peak_ = 0;
}

VkDeviceSize StagingRing::take(VkDeviceSize want, VkDeviceSize& got) noexcept {
  const VkDeviceSize offset = used_;
  got = std::min(want, buf_.size - used_);
  used_ = std::min(buf_.size, (used_ + got + kAlign - 1) / kAlign * kAlign);
  peak_ = std::max(peak_, used_);
  return offset;
}

}  // namespace resoct::vk::detail
