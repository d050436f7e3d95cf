#include "device_memory.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "resoct/error.hpp"

namespace resoct::vk::detail {

std::uint32_t buffer_memory_type(const Context& c, std::uint32_t type_bits) {
  const VkMemoryPropertyFlags host =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  for (VkMemoryPropertyFlags want : {host | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, host}) {
    for (std::uint32_t i = 0; i < c.memory.memoryTypeCount; ++i) {
      if ((type_bits & (1u << i)) && (c.memory.memoryTypes[i].propertyFlags & want) == want)
        return i;
    }
  }
  throw Error(ErrorCode::device, "vulkan: no host-visible coherent memory type for buffers");
}

void check_budget(const Context& c, VkDeviceSize bytes) {
  const std::uint32_t heap = c.memory.memoryTypes[buffer_memory_type(c, ~0u)].heapIndex;
  VkDeviceSize available = c.memory.memoryHeaps[heap].size;
  if (c.has_budget) {
    VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
    VkPhysicalDeviceMemoryProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2};
    p2.pNext = &budget;
    vkGetPhysicalDeviceMemoryProperties2(c.physical, &p2);
    const VkDeviceSize b = budget.heapBudget[heap], u = budget.heapUsage[heap];
    available = b > u ? b - u : 0;
  }
  if (bytes > available) {
    throw Error(ErrorCode::out_of_memory,
                "vulkan: device buffers of " + std::to_string(bytes) + " bytes exceed the " +
                    std::to_string(available) + " bytes available in memory heap " +
                    std::to_string(heap) + (c.has_budget ? " (VK_EXT_memory_budget)" : ""));
  }
}

Buffer create_buffer(const Context& c, VkDeviceSize bytes, const char* what) {
  Buffer b;
  b.size = std::max<VkDeviceSize>(bytes, 16);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = b.size;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
              VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  try {
    check(vkCreateBuffer(c.device, &bci, nullptr, &b.buffer), std::string("creating ") + what);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(c.device, b.buffer, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = buffer_memory_type(c, req.memoryTypeBits);
    check(vkAllocateMemory(c.device, &mai, nullptr, &b.memory), std::string("allocating ") + what);
    check(vkBindBufferMemory(c.device, b.buffer, b.memory, 0), std::string("binding ") + what);
    check(vkMapMemory(c.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped),
          std::string("mapping ") + what);
  } catch (...) {
    destroy_buffer(c, b);
    throw;
  }
  std::memset(b.mapped, 0, std::size_t(b.size));
  return b;
}

void destroy_buffer(const Context& c, Buffer& b) noexcept {
  if (b.memory != VK_NULL_HANDLE) vkFreeMemory(c.device, b.memory, nullptr);
  if (b.buffer != VK_NULL_HANDLE) vkDestroyBuffer(c.device, b.buffer, nullptr);
  b = Buffer{};
}

}  // namespace resoct::vk::detail
