#pragma once
/// \file
/// Vulkan device discovery. This header does not include <vulkan/vulkan.h>: device records are
/// plain data so that tools can list devices without Vulkan headers.

#include <cstdint>
#include <string>
#include <vector>

namespace resoct::vk {

struct DeviceInfo {
  std::uint32_t index = 0;               ///< position in vkEnumeratePhysicalDevices order
  std::string name;                      ///< VkPhysicalDeviceProperties::deviceName
  std::string type;                      ///< "discrete", "integrated", "virtual", "cpu" or "other"
  std::uint32_t api_version = 0;         ///< VK_MAKE_API_VERSION-encoded
  std::uint64_t device_local_bytes = 0;  ///< sum of DEVICE_LOCAL heap sizes
  bool has_compute_queue = false;
};

/// Lists the Vulkan devices the loader reports. Returns an empty list when no loader or no ICD is
/// present; throws Error(device) only when the loader itself fails in an unexpected way.
/// Thread-safe.
std::vector<DeviceInfo> list_devices();

/// "1.3.239" from an encoded API version.
std::string api_version_string(std::uint32_t v);

}  // namespace resoct::vk
