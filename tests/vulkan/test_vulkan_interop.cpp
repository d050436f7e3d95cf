// The interop constructor: the backend renders with an application's instance and device (here
// created with the validation layer and a messenger of the test's own) and matches the CPU
// backend like the self-created backend does.
#include <atomic>
#include <cstdio>
#include <vector>

#include <vulkan/vulkan.h>

#include "vulkan_test_util.hpp"
#include "support/expect_error.hpp"
#include "resoct/procedural_source.hpp"
#include "resoct/scene.hpp"
#include "support/vulkan_required.hpp"

namespace resoct::test {
namespace {

std::atomic<int> g_messages{0};

VKAPI_ATTR VkBool32 VKAPI_CALL count_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void*) {
  g_messages.fetch_add(1);
  std::fprintf(stderr, "validation: %s\n", data && data->pMessage ? data->pMessage : "");
  return VK_FALSE;
}

TEST(VulkanInterop, RendersWithAnApplicationDevice) {
  if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_2;
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* ext[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                       VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  // Synchronization validation too: the backend's barriers must satisfy it on a foreign device.
  const VkValidationFeatureEnableEXT sync =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pNext = &features;
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = 1;
  ici.ppEnabledLayerNames = &layer;
  ici.enabledExtensionCount = 2;
  ici.ppEnabledExtensionNames = ext;
  VkInstance instance = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType =
      VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  mci.pfnUserCallback = count_message;
  auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
  auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
  ASSERT_NE(create_messenger, nullptr);
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  ASSERT_EQ(create_messenger(instance, &mci, nullptr, &messenger), VK_SUCCESS);

  std::uint32_t count = 1;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  vkEnumeratePhysicalDevices(instance, &count, &physical);
  ASSERT_NE(physical, VK_NULL_HANDLE);
  std::uint32_t qn = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &qn, nullptr);
  std::vector<VkQueueFamilyProperties> q(qn);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &qn, q.data());
  std::uint32_t family = 0;
  while (family < qn && (q[family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) ++family;
  ASSERT_LT(family, qn);
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  VkDevice device = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDevice(physical, &dci, nullptr, &device), VK_SUCCESS);

  {
    vk::VulkanBackend gpu(instance, physical, device, family);
    BrickLayout bl;
    bl.brick_size = glm::uvec3(8);
    bl.halo = 1;
    ProceduralSource src("procedural:sphere:24x24x24", bl);
    Scene scene = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
    scene.viewport = Viewport{24, 20};
    ResidentScene rs(src, {0});
    cpu::CpuBackend cpu(1);
    OracleDiff d;
    const FrameResult a = render_on(cpu, rs, scene, {});
    const FrameResult b = render_on(gpu, rs, scene, {});
    EXPECT_GT(a.stats.samples, 0u);
    expect_same_frame(a, b, "interop sphere", d);
  }
  // The backend must not have destroyed the caller's handles.
  EXPECT_EQ(vkDeviceWaitIdle(device), VK_SUCCESS);
  vkDestroyDevice(device, nullptr);
  destroy_messenger(instance, messenger, nullptr);
  vkDestroyInstance(instance, nullptr);
  EXPECT_EQ(g_messages.load(), 0);
}

TEST(VulkanInterop, NullHandlesAreRejected) {
  EXPECT_RESOCT_ERROR(vk::VulkanBackend(VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, 0),
                      ErrorCode::invalid_argument, "device");
}

}  // namespace
}  // namespace resoct::test
