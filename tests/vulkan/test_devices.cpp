#include <gtest/gtest.h>

#include <algorithm>

#include "resoct/vulkan/devices.hpp"
#include "support/vulkan_required.hpp"

using namespace resoct;

TEST(VulkanDevices, ListsAComputeCapableDeviceOrSkipsWithAReason) {
  const auto devices = vk::list_devices();
  if (devices.empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device or ICD on this machine");
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, i);
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_GE(devices[i].api_version, (1u << 22) | (1u << 12)) << "below Vulkan 1.1";
  }
  EXPECT_TRUE(std::any_of(devices.begin(), devices.end(),
                          [](const vk::DeviceInfo& d) { return d.has_compute_queue; }));
}

TEST(VulkanDevices, ApiVersionStringDecodes) {
  EXPECT_EQ(vk::api_version_string((1u << 22) | (3u << 12) | 239u), "1.3.239");
}
