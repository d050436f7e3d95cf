#include "resoct/vulkan/devices.hpp"

#include <vulkan/vulkan.h>

#include "resoct/base/error.hpp"

namespace resoct::vk {

namespace {
std::string type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}
}  // namespace

std::string api_version_string(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

std::vector<DeviceInfo> list_devices() {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "resoct";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult r = vkCreateInstance(&ci, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED) return {};
  if (r != VK_SUCCESS) {
    throw Error(ErrorCode::device, "vkCreateInstance failed with VkResult " + std::to_string(r));
  }
  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> physical(count);
  vkEnumeratePhysicalDevices(instance, &count, physical.data());

  std::vector<DeviceInfo> out;
  for (std::uint32_t i = 0; i < count; ++i) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical[i], &props);
    VkPhysicalDeviceMemoryProperties mem;
    vkGetPhysicalDeviceMemoryProperties(physical[i], &mem);
    std::uint32_t qcount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical[i], &qcount, nullptr);
    std::vector<VkQueueFamilyProperties> queues(qcount);
    vkGetPhysicalDeviceQueueFamilyProperties(physical[i], &qcount, queues.data());

    DeviceInfo d;
    d.index = i;
    d.name = props.deviceName;
    d.type = type_name(props.deviceType);
    d.api_version = props.apiVersion;
    for (std::uint32_t h = 0; h < mem.memoryHeapCount; ++h) {
      if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) {
        d.device_local_bytes += mem.memoryHeaps[h].size;
      }
    }
    for (const auto& q : queues) d.has_compute_queue |= (q.queueFlags & VK_QUEUE_COMPUTE_BIT) != 0;
    out.push_back(std::move(d));
  }
  vkDestroyInstance(instance, nullptr);
  return out;
}

}  // namespace resoct::vk
