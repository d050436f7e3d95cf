#pragma once
// Internal: device memory of the Vulkan backend — memory-type choice per use, the heap budget
// check (VK_EXT_memory_budget when enabled) and buffers with their own allocation. The backend
// holds a few dozen buffers, so one allocation per buffer stays far below
// maxMemoryAllocationCount and needs no sub-allocator.
#include <cstdint>
#include <map>

#include <vulkan/vulkan.h>

#include "vk_context.hpp"

namespace resoct::vk::detail {

/// What a buffer is for; decides its memory type.
enum class MemoryUse : std::uint8_t {
  device,    ///< read/written by shaders and transfers only: DEVICE_LOCAL, preferably not
             ///< host-visible (a discrete GPU's resizable-BAR heap is small)
  upload,    ///< written by the host, read by transfers/shaders: HOST_VISIBLE | HOST_COHERENT,
             ///< preferably not DEVICE_LOCAL (system memory, not the BAR heap)
  readback,  ///< written by transfers, read by the host: HOST_VISIBLE, preferably HOST_CACHED
};

/// A buffer and its allocation; `mapped` is set for host-visible uses.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
  bool coherent = true;  ///< false: reads need invalidate() first
};

/// The memory type index for `use` among `type_bits` (a VkMemoryRequirements mask). Throws
/// Error(device) when no type qualifies.
std::uint32_t memory_type(const Context& c, std::uint32_t type_bits, MemoryUse use);
/// Bytes still available in `heap`: VK_EXT_memory_budget's budget minus usage when the extension
/// is enabled, else the heap size (the backend's earlier allocations are not subtracted then).
VkDeviceSize heap_available(const Context& c, std::uint32_t heap);
/// The heap a buffer of `use` would be allocated from (for budget planning).
std::uint32_t heap_of(const Context& c, MemoryUse use);
/// Throws Error(out_of_memory) naming the heap when the planned bytes per heap do not fit.
void check_budget(const Context& c, const std::map<std::uint32_t, VkDeviceSize>& bytes_per_heap);

/// Creates a buffer of at least `bytes` (>= 16) with its own allocation of `use`'s memory type,
/// persistently mapped for host-visible uses. Throws Error(out_of_memory) when the heap budget or
/// the driver refuses, naming `what`.
Buffer create_buffer(const Context& c, VkDeviceSize bytes, VkBufferUsageFlags usage, MemoryUse use,
                     const char* what);
void destroy_buffer(const Context& c, Buffer& b) noexcept;
/// Makes device writes to a mapped, non-coherent buffer visible to the host (no-op if coherent).
void invalidate(const Context& c, const Buffer& b);

}  // namespace resoct::vk::detail
