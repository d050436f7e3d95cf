#pragma once
// Internal: the Vulkan instance/device a VulkanBackend renders with (own or adopted), the
// validation messenger, and host-visible storage buffers.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "resoct/backend.hpp"

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

/// A persistently mapped, host-coherent storage buffer.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

/// The memory type buffers use: host-visible + coherent, device-local where such a type exists
/// (integrated GPUs, CPU devices, resizable BAR), else plain host-visible.
std::uint32_t buffer_memory_type(const Context& c, std::uint32_t type_bits);
/// Throws Error(out_of_memory) when `bytes` more would not fit the heap of the buffer memory
/// type (its VK_EXT_memory_budget budget where available, else its size).
void check_budget(const Context& c, VkDeviceSize bytes);
Buffer create_buffer(const Context& c, VkDeviceSize bytes, const char* what);
void destroy_buffer(const Context& c, Buffer& b) noexcept;

}  // namespace resoct::vk::detail
