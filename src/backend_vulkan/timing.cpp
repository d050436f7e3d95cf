#include "timing.hpp"

#include <array>

namespace resoct::vk::detail {

GpuTimer::GpuTimer(const Context& c) : c_(c) {
  if (c.timestamp_bits == 0) return;
  VkQueryPoolCreateInfo qpci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qpci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qpci.queryCount = 2;
  check(vkCreateQueryPool(c.device, &qpci, nullptr, &pool_), "vkCreateQueryPool");
}

GpuTimer::~GpuTimer() {
  if (pool_) vkDestroyQueryPool(c_.device, pool_, nullptr);
}

void GpuTimer::begin(VkCommandBuffer cmd) const {
  if (!pool_) return;
  vkCmdResetQueryPool(cmd, pool_, 0, 2);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, 0);
}

void GpuTimer::end(VkCommandBuffer cmd) const {
  if (pool_) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 1);
}

double GpuTimer::ms() const {
  if (!pool_) return 0.0;
  std::array<std::uint64_t, 2> ts{};
  check(vkGetQueryPoolResults(c_.device, pool_, 0, 2, sizeof(ts), ts.data(), sizeof(std::uint64_t),
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  // Timestamps wrap at timestampValidBits.
  const std::uint64_t mask =
      c_.timestamp_bits >= 64 ? ~0ull : (std::uint64_t(1) << c_.timestamp_bits) - 1u;
  const std::uint64_t ticks = ((ts[1] & mask) - (ts[0] & mask)) & mask;
  return double(ticks) * double(c_.props.limits.timestampPeriod) * 1e-6;
}

}  // namespace resoct::vk::detail
