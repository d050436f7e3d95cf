#pragma once
// Internal: device time of recorded commands through timestamp queries.
#include <cstdint>

#include <vulkan/vulkan.h>

#include "vk_context.hpp"

namespace resoct::vk::detail {

/// Two timestamps around a command range. Inactive (every call a no-op, ms() = 0) when the
/// queue family has no timestamp support.
class GpuTimer {
 public:
  explicit GpuTimer(const Context& c);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  /// Records the query reset and the first timestamp (top of pipe).
  void begin(VkCommandBuffer cmd) const;
  /// Records the second timestamp (bottom of pipe).
  void end(VkCommandBuffer cmd) const;
  /// Milliseconds between the two timestamps of the last submission (waits for the results).
  double ms() const;

 private:
  const Context& c_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
};

}  // namespace resoct::vk::detail
