#pragma once
// Internal: device memory of the Vulkan backend — memory-type choice, the heap budget check and
// storage buffers.
#include <cstdint>

#include <vulkan/vulkan.h>

#include "vk_context.hpp"

namespace resoct::vk::detail {

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
