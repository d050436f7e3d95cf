#pragma once
// Internal: the Vulkan instance/device a VulkanBackend renders with (own or adopted), the
// validation messenger, and the VkResult check.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "resoct/backend/backend.hpp"

namespace resoct::vk::detail {

/// Throws Error(out_of_memory) for VK_ERROR_OUT_OF_*_MEMORY, Error(device) for anything else
/// that is not VK_SUCCESS (device loss included), naming `what`.
void check(VkResult r, const std::string& what);

struct Context {
  bool owns = false;
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties props{};
  VkPhysicalDeviceMemoryProperties memory{};
  bool has_budget = false;
  std::uint32_t timestamp_bits = 0;
  std::uint32_t loop_limit = 0;  ///< loop back-edges per invocation the driver allows (0 = none)
  std::atomic<std::uint64_t> messages{0};
  mutable std::mutex log_mutex;
  std::vector<std::string> log;

  Context() = default;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context();
};

/// Creates an instance and a device as VulkanBackend(options) documents.
std::unique_ptr<Context> create_context(const BackendOptions& options);
/// Wraps caller-owned handles.
std::unique_ptr<Context> adopt_context(VkInstance instance, VkPhysicalDevice physical,
                                       VkDevice device, std::uint32_t family);

}  // namespace resoct::vk::detail
