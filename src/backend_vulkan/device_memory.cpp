#include "device_memory.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <utility>

#include "resoct/base/error.hpp"

namespace resoct::vk::detail {

namespace {

constexpr VkMemoryPropertyFlags kHostVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
constexpr VkMemoryPropertyFlags kCoherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
constexpr VkMemoryPropertyFlags kDeviceLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;

struct Preference {
  VkMemoryPropertyFlags required;
  VkMemoryPropertyFlags avoided;
};

// Preferences per use, best first; the first type (in the driver's order, which the spec sorts
// by performance among equal flags) matching a preference wins.
std::array<Preference, 3> preferences(MemoryUse use) {
  switch (use) {
    case MemoryUse::device: return {{{kDeviceLocal, kHostVisible}, {kDeviceLocal, 0}, {0, 0}}};
    case MemoryUse::upload:
      return {{{kHostVisible | kCoherent, kDeviceLocal},
               {kHostVisible | kCoherent, 0},
               {kHostVisible | kCoherent, 0}}};
    case MemoryUse::readback:
      return {{{kHostVisible | kCached | kCoherent, 0},
               {kHostVisible | kCached, 0},
               {kHostVisible | kCoherent, 0}}};
  }
  return {};
}

const char* use_name(MemoryUse use) {
  switch (use) {
    case MemoryUse::device: return "device-local";
    case MemoryUse::upload: return "host-visible coherent";
    case MemoryUse::readback: return "host-visible";
  }
  return "";
}

}  // namespace

std::uint32_t memory_type(const Context& c, std::uint32_t type_bits, MemoryUse use) {
  for (const Preference& p : preferences(use)) {
    for (std::uint32_t i = 0; i < c.memory.memoryTypeCount; ++i) {
      const VkMemoryPropertyFlags f = c.memory.memoryTypes[i].propertyFlags;
      if ((type_bits & (1u << i)) && (f & p.required) == p.required && (f & p.avoided) == 0) {
        return i;
      }
    }
  }
  throw Error(ErrorCode::device,
              std::string("vulkan: no ") + use_name(use) + " memory type for this buffer");
}

VkDeviceSize heap_available(const Context& c, std::uint32_t heap) {
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
  return available;
}

std::uint32_t heap_of(const Context& c, MemoryUse use) {
  return c.memory.memoryTypes[memory_type(c, ~0u, use)].heapIndex;
}

void check_budget(const Context& c, const std::map<std::uint32_t, VkDeviceSize>& bytes_per_heap) {
  for (const auto& [heap, bytes] : bytes_per_heap) {
    const VkDeviceSize available = heap_available(c, heap);
    if (bytes > available) {
      throw Error(ErrorCode::out_of_memory,
                  "vulkan: device buffers of " + std::to_string(bytes) + " bytes exceed the " +
                      std::to_string(available) + " bytes available in memory heap " +
                      std::to_string(heap) + (c.has_budget ? " (VK_EXT_memory_budget)" : ""));
    }
  }
}

Buffer create_buffer(const Context& c, VkDeviceSize bytes, VkBufferUsageFlags usage, MemoryUse use,
                     const char* what) {
  Buffer b;
  b.size = std::max<VkDeviceSize>(bytes, 16);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = b.size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  try {
    check(vkCreateBuffer(c.device, &bci, nullptr, &b.buffer), std::string("creating ") + what);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(c.device, b.buffer, &req);
    const std::uint32_t type = memory_type(c, req.memoryTypeBits, use);
    const std::uint32_t heap = c.memory.memoryTypes[type].heapIndex;
    check_budget(c, {{heap, req.size}});
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = type;
    check(vkAllocateMemory(c.device, &mai, nullptr, &b.memory), std::string("allocating ") + what);
    check(vkBindBufferMemory(c.device, b.buffer, b.memory, 0), std::string("binding ") + what);
    const VkMemoryPropertyFlags flags = c.memory.memoryTypes[type].propertyFlags;
    if (use != MemoryUse::device) {
      check(vkMapMemory(c.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped),
            std::string("mapping ") + what);
      b.coherent = (flags & kCoherent) != 0;
    }
  } catch (const Error& e) {
    destroy_buffer(c, b);
    if (e.code() == ErrorCode::out_of_memory) {
      throw Error(ErrorCode::out_of_memory, std::string(e.what()) + " (" + what + ")");
    }
    throw;
  }
  return b;
}

void destroy_buffer(const Context& c, Buffer& b) noexcept {
  if (b.memory != VK_NULL_HANDLE) vkFreeMemory(c.device, b.memory, nullptr);
  if (b.buffer != VK_NULL_HANDLE) vkDestroyBuffer(c.device, b.buffer, nullptr);
  b = Buffer{};
}

void invalidate(const Context& c, const Buffer& b) {
  if (b.coherent || b.memory == VK_NULL_HANDLE) return;
  VkMappedMemoryRange r{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  r.memory = b.memory;
  r.offset = 0;
  r.size = VK_WHOLE_SIZE;
  check(vkInvalidateMappedMemoryRanges(c.device, 1, &r), "vkInvalidateMappedMemoryRanges");
}

}  // namespace resoct::vk::detail
