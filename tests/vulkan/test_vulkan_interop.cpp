// The interop constructor: the backend renders with an application's instance and device (here
// created with the validation layer and a messenger of the test's own) and matches the CPU
// backend like the self-created backend does, alone and as a Renderer's backend object.
#include <atomic>
#include <cstdio>
#include <cstring>
#include <vector>

#include <vulkan/vulkan.h>

#include "vulkan_test_util.hpp"
#include "support/expect_error.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
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

// An application's instance and device: the validation layer with synchronization validation and
// a messenger of the test's own that counts every warning and error.
struct AppDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t family = 0;

  AppDevice() = default;
  AppDevice(const AppDevice&) = delete;
  AppDevice& operator=(const AppDevice&) = delete;
  ~AppDevice() { destroy(); }

  void destroy() {
    if (device != VK_NULL_HANDLE) vkDestroyDevice(device, nullptr);
    if (messenger != VK_NULL_HANDLE) destroy_messenger(instance, messenger, nullptr);
    if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
    device = VK_NULL_HANDLE;
    messenger = VK_NULL_HANDLE;
    instance = VK_NULL_HANDLE;
  }
};

// Fills `d`; a failed step is a fatal failure of the calling test (check HasFatalFailure()).
void create_app_device(AppDevice& d) {
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
  ASSERT_EQ(vkCreateInstance(&ici, nullptr, &d.instance), VK_SUCCESS);
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType =
      VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  mci.pfnUserCallback = count_message;
  auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(d.instance, "vkCreateDebugUtilsMessengerEXT"));
  d.destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(d.instance, "vkDestroyDebugUtilsMessengerEXT"));
  ASSERT_NE(create_messenger, nullptr);
  ASSERT_EQ(create_messenger(d.instance, &mci, nullptr, &d.messenger), VK_SUCCESS);

  std::uint32_t count = 1;
  vkEnumeratePhysicalDevices(d.instance, &count, &d.physical);
  ASSERT_NE(d.physical, VK_NULL_HANDLE);
  std::uint32_t qn = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &qn, nullptr);
  std::vector<VkQueueFamilyProperties> q(qn);
  vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &qn, q.data());
  while (d.family < qn && (q[d.family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) ++d.family;
  ASSERT_LT(d.family, qn);
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = d.family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  ASSERT_EQ(vkCreateDevice(d.physical, &dci, nullptr, &d.device), VK_SUCCESS);
}

// What an application does with FrameOutput::device: records its own copy of the frame's device
// buffer into host-visible memory on queue 0 of its family, behind the barrier DeviceImage asks
// for, and reads it. A failed step is a fatal failure of the calling test.
void copy_device_image(const AppDevice& d, const DeviceImage& image, std::vector<glm::vec4>& out) {
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = image.bytes;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer host = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(d.device, &bci, nullptr, &host), VK_SUCCESS);
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(d.device, host, &req);
  VkPhysicalDeviceMemoryProperties mp{};
  vkGetPhysicalDeviceMemoryProperties(d.physical, &mp);
  const VkMemoryPropertyFlags want =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  std::uint32_t type = 0;
  while (type < mp.memoryTypeCount && (((req.memoryTypeBits >> type) & 1u) == 0 ||
                                       (mp.memoryTypes[type].propertyFlags & want) != want)) {
    ++type;
  }
  ASSERT_LT(type, mp.memoryTypeCount);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(d.device, &mai, nullptr, &memory), VK_SUCCESS);
  ASSERT_EQ(vkBindBufferMemory(d.device, host, memory, 0), VK_SUCCESS);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = d.family;
  VkCommandPool pool = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateCommandPool(d.device, &pci, nullptr, &pool), VK_SUCCESS);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(d.device, &cai, &cmd), VK_SUCCESS);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  ASSERT_EQ(vkBeginCommandBuffer(cmd, &begin), VK_SUCCESS);
  VkBufferMemoryBarrier from_kernel{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  from_kernel.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  from_kernel.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  from_kernel.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  from_kernel.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  from_kernel.buffer = vk::buffer_of(image);
  from_kernel.offset = image.offset;
  from_kernel.size = image.bytes;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                       0, nullptr, 1, &from_kernel, 0, nullptr);
  const VkBufferCopy region{image.offset, 0, image.bytes};
  vkCmdCopyBuffer(cmd, vk::buffer_of(image), host, 1, &region);
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &to_host, 0, nullptr, 0, nullptr);
  ASSERT_EQ(vkEndCommandBuffer(cmd), VK_SUCCESS);
  VkQueue queue = VK_NULL_HANDLE;
  vkGetDeviceQueue(d.device, d.family, 0, &queue);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  ASSERT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  void* mapped = nullptr;
  ASSERT_EQ(vkMapMemory(d.device, memory, 0, image.bytes, 0, &mapped), VK_SUCCESS);
  out.resize(std::size_t(image.bytes / sizeof(glm::vec4)));
  std::memcpy(out.data(), mapped, std::size_t(image.bytes));
  vkUnmapMemory(d.device, memory);
  vkDestroyCommandPool(d.device, pool, nullptr);
  vkDestroyBuffer(d.device, host, nullptr);
  vkFreeMemory(d.device, memory, nullptr);
}

// Tests that render on an application's device open it first; TearDown then checks that the
// backend left the caller's handles usable and the validation layer silent.
class VulkanInterop : public ::testing::Test {
 protected:
  /// Creates app_, or skips (fails with RESOCT_REQUIRE_VULKAN=1) without a device; the caller
  /// returns when IsSkipped() or HasFatalFailure().
  void open_device() {
    if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
    g_messages = 0;
    create_app_device(app_);
  }

  void TearDown() override {
    if (app_.device == VK_NULL_HANDLE) return;
    EXPECT_EQ(vkDeviceWaitIdle(app_.device), VK_SUCCESS);
    app_.destroy();
    EXPECT_EQ(g_messages.load(), 0);
  }

  AppDevice app_;
};

TEST_F(VulkanInterop, RendersWithAnApplicationDevice) {
  open_device();
  if (IsSkipped() || HasFatalFailure()) return;
  vk::VulkanBackend gpu(app_.instance, app_.physical, app_.device, app_.family);
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

// The interop form as a backend object: a Renderer drives the application's device through the
// whole frame loop (configure, uploads, requests) and converges to the CPU renderer's image.
TEST_F(VulkanInterop, RendererTakesAnApplicationDeviceBackend) {
  open_device();
  if (IsSkipped() || HasFatalFailure()) return;
  const std::shared_ptr<const BrickSource> src =
      make_procedural_source("procedural:tubes:48x48x48", BrickLayout{glm::uvec3(16), 1});
  const Scene scene = overview_scene(src->hierarchy().volume(), Viewport{40, 32});
  ViewerOptions o;
  o.loader_threads = 0;
  Renderer on_gpu(src, vk::make_backend(app_.instance, app_.physical, app_.device, app_.family), o);
  Renderer on_cpu(src, cpu::make_backend(1), o);
  EXPECT_EQ(inspect::backend(on_gpu).name(), "vulkan");
  const ConvergeReport a = on_cpu.render_until_converged(scene, 64);
  const ConvergeReport b = on_gpu.render_until_converged(scene, 64);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_GT(a.last.stats.backend.samples, 0u);
  EXPECT_EQ(a.last.stats.backend.samples, b.last.stats.backend.samples);
  const ImageDiff diff = compare_images(a.last.image, b.last.image);
  for (int c = 0; c < 4; ++c) EXPECT_LE(diff.max_abs[c], kVulkanColourTolerance) << c;
}

// FrameOutput::device: the converged frame stays in the backend's buffer (no image, no 8-bit
// pixels on the host), and what the application copies out of it equals, bit for bit, the image
// a read-back renderer on the same device returns.
TEST_F(VulkanInterop, DeviceOutputStaysOnTheDeviceAndEqualsTheReadBack) {
  open_device();
  if (IsSkipped() || HasFatalFailure()) return;
  const std::shared_ptr<const BrickSource> src =
      make_procedural_source("procedural:tubes:48x48x48", BrickLayout{glm::uvec3(16), 1});
  const Scene scene = overview_scene(src->hierarchy().volume(), Viewport{40, 32});
  ViewerOptions o;
  o.loader_threads = 0;
  ViewerOptions on_device_options = o;
  on_device_options.output = FrameOutput::device;
  Renderer read_back(src, vk::make_backend(app_.instance, app_.physical, app_.device, app_.family),
                     o);
  Renderer on_device(src, vk::make_backend(app_.instance, app_.physical, app_.device, app_.family),
                     on_device_options);
  const ConvergeReport a = read_back.render_until_converged(scene, 64);
  const ConvergeReport b = on_device.render_until_converged(scene, 64);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.last.device_image.handle, 0u);
  const FrameReport& f = b.last;
  EXPECT_EQ(f.width, 40u);
  EXPECT_EQ(f.height, 32u);
  EXPECT_EQ(f.image.width(), 0u);
  EXPECT_TRUE(f.image.pixels().empty());
  EXPECT_TRUE(f.rgba8.empty());
  ASSERT_NE(f.device_image.handle, 0u);
  EXPECT_EQ(f.device_image.width, 40u);
  EXPECT_EQ(f.device_image.height, 32u);
  EXPECT_EQ(f.device_image.bytes, 40u * 32u * sizeof(glm::vec4));
  EXPECT_EQ(vk::handle_of(vk::buffer_of(f.device_image)), f.device_image.handle);
  EXPECT_EQ(f.stats.backend.samples, a.last.stats.backend.samples);
  std::vector<glm::vec4> pixels;
  copy_device_image(app_, f.device_image, pixels);
  if (HasFatalFailure()) return;
  ASSERT_EQ(pixels.size(), a.last.image.pixels().size());
  EXPECT_EQ(
      std::memcmp(pixels.data(), a.last.image.pixels().data(), pixels.size() * sizeof(glm::vec4)),
      0);
  EXPECT_GT(a.last.image.at(20, 16).a, 0.0f);
}

TEST_F(VulkanInterop, NullHandlesAreRejected) {
  EXPECT_RESOCT_ERROR(vk::VulkanBackend(VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, 0),
                      ErrorCode::invalid_argument, "device");
}

}  // namespace
}  // namespace resoct::test
