#include "vk_context.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>

#include "resoct/base/error.hpp"
#include "resoct/vulkan/devices.hpp"

namespace resoct::vk::detail {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr std::size_t kMaxLoggedMessages = 64;

VKAPI_ATTR VkBool32 VKAPI_CALL on_debug_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                void* user) {
  auto* c = static_cast<Context*>(user);
  if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                  VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
    c->messages.fetch_add(1, std::memory_order_relaxed);
    std::lock_guard lock(c->log_mutex);
    if (c->log.size() < kMaxLoggedMessages) {
      c->log.emplace_back(data && data->pMessage ? data->pMessage : "(no message)");
    }
  }
  return VK_FALSE;
}

bool layer_available(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

bool layer_extension_available(const char* layer, const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceExtensionProperties(layer, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateInstanceExtensionProperties(layer, &n, ext.data());
  return std::any_of(ext.begin(), ext.end(), [&](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, name) == 0;
  });
}

bool device_extension_available(VkPhysicalDevice p, const char* name) {
  std::uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(p, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateDeviceExtensionProperties(p, nullptr, &n, ext.data());
  return std::any_of(ext.begin(), ext.end(), [&](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, name) == 0;
  });
}

std::string lower(std::string s) {
  for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

int type_rank(const std::string& type) {
  if (type == "discrete") return 0;
  if (type == "integrated") return 1;
  if (type == "virtual") return 2;
  if (type == "cpu") return 3;
  return 4;
}

// Index into `devices` chosen by the BackendOptions::device rule.
std::uint32_t select_device(const std::vector<DeviceInfo>& devices, const std::string& want) {
  std::string names;
  for (const auto& d : devices)
    names += (names.empty() ? "" : ", ") + std::to_string(d.index) + ": " + d.name;
  if (devices.empty()) throw Error(ErrorCode::device, "device: no Vulkan device is available");
  if (want.empty()) {
    std::uint32_t best = ~0u;
    for (std::uint32_t i = 0; i < devices.size(); ++i) {
      if (!devices[i].has_compute_queue) continue;
      if (best == ~0u || type_rank(devices[i].type) < type_rank(devices[best].type)) best = i;
    }
    if (best == ~0u) throw Error(ErrorCode::device, "device: no Vulkan device has a compute queue");
    return best;
  }
  const bool numeric = std::all_of(want.begin(), want.end(), [](char ch) {
    return std::isdigit(static_cast<unsigned char>(ch));
  });
  if (numeric && want.size() < 9) {
    const auto i = std::uint32_t(std::stoul(want));
    if (i < devices.size() && devices[i].has_compute_queue) return i;
  } else {
    for (std::uint32_t i = 0; i < devices.size(); ++i) {
      if (devices[i].has_compute_queue &&
          lower(devices[i].name).find(lower(want)) != std::string::npos) {
        return i;
      }
    }
  }
  throw Error(ErrorCode::device, "device: no compute-capable Vulkan device matches \"" + want +
                                     "\" (available: " + names + ")");
}

void fill_properties(Context& c) {
  vkGetPhysicalDeviceProperties(c.physical, &c.props);
  vkGetPhysicalDeviceMemoryProperties(c.physical, &c.memory);
  std::uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(c.physical, &n, nullptr);
  std::vector<VkQueueFamilyProperties> q(n);
  vkGetPhysicalDeviceQueueFamilyProperties(c.physical, &n, q.data());
  if (c.family >= n || (q[c.family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) {
    throw Error(ErrorCode::device,
                "device: queue family " + std::to_string(c.family) + " has no compute queue");
  }
  c.timestamp_bits = c.props.limits.timestampPeriod > 0.0f ? q[c.family].timestampValidBits : 0u;
  if (c.props.apiVersion >= VK_API_VERSION_1_2) {
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p2.pNext = &driver;
    vkGetPhysicalDeviceProperties2(c.physical, &p2);
    // llvmpipe's guard against endless loops (Mesa gallivm LP_MAX_TGSI_LOOP_ITERATIONS): one
    // counter per invocation batch, decremented at every loop back-edge of the shader.
    if (driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE) c.loop_limit = 65535;
  }
  vkGetDeviceQueue(c.device, c.family, 0, &c.queue);
}

}  // namespace

void check(VkResult r, const std::string& what) {
  if (r == VK_SUCCESS) return;
  if (r == VK_ERROR_OUT_OF_HOST_MEMORY || r == VK_ERROR_OUT_OF_DEVICE_MEMORY) {
    throw Error(ErrorCode::out_of_memory,
                "vulkan: " + what + " ran out of memory (VkResult " + std::to_string(int(r)) + ")");
  }
  if (r == VK_ERROR_DEVICE_LOST) throw Error(ErrorCode::device, "vulkan: device lost in " + what);
  throw Error(ErrorCode::device,
              "vulkan: " + what + " failed (VkResult " + std::to_string(int(r)) + ")");
}

Context::~Context() {
  if (!owns) return;
  if (device != VK_NULL_HANDLE) vkDestroyDevice(device, nullptr);
  if (messenger != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance, messenger, nullptr);
  }
  if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
}

std::unique_ptr<Context> create_context(const BackendOptions& options) {
  const char* env = std::getenv("RESOCT_VK_VALIDATION");
  const bool validation = options.validation || (env && std::string(env) == "1");
  const std::vector<DeviceInfo> devices = list_devices();
  const std::uint32_t index = select_device(devices, options.device);

  auto c = std::make_unique<Context>();
  c->owns = true;
  if (validation && !layer_available(kValidationLayer)) {
    throw Error(ErrorCode::device, "validation: VK_LAYER_KHRONOS_validation is not installed");
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "resoct";
  app.apiVersion = VK_API_VERSION_1_2;
  const char* layers[] = {kValidationLayer};
  const char* instance_ext[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  // Synchronization validation as well: missing or wrong barriers between the staged copies,
  // scatters, the dispatch and the readback are reported like any other validation error.
  const VkValidationFeatureEnableEXT sync =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync;
  if (validation) {
    const bool has_features =
        layer_extension_available(kValidationLayer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = layers;
    ici.enabledExtensionCount = has_features ? 2u : 1u;
    ici.ppEnabledExtensionNames = instance_ext;
    if (has_features) ici.pNext = &features;
  }
  check(vkCreateInstance(&ici, nullptr, &c->instance), "vkCreateInstance");
  if (validation) {
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mci.pfnUserCallback = on_debug_message;
    mci.pUserData = c.get();
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(c->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) throw Error(ErrorCode::device, "validation: VK_EXT_debug_utils is unavailable");
    check(create(c->instance, &mci, nullptr, &c->messenger), "vkCreateDebugUtilsMessengerEXT");
  }
  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(c->instance, &count, nullptr);
  std::vector<VkPhysicalDevice> physical(count);
  vkEnumeratePhysicalDevices(c->instance, &count, physical.data());
  if (index >= count) throw Error(ErrorCode::device, "device: the device list changed");
  c->physical = physical[index];

  std::uint32_t qn = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(c->physical, &qn, nullptr);
  std::vector<VkQueueFamilyProperties> queues(qn);
  vkGetPhysicalDeviceQueueFamilyProperties(c->physical, &qn, queues.data());
  // Prefer a compute-only family (async compute on discrete GPUs), else any with compute.
  std::uint32_t family = ~0u;
  for (std::uint32_t i = 0; i < qn; ++i) {
    if ((queues[i].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) continue;
    if (family == ~0u || (queues[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) == 0) family = i;
  }
  if (family == ~0u) throw Error(ErrorCode::device, "device: the device has no compute queue");
  c->family = family;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  c->has_budget = device_extension_available(c->physical, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
  const char* device_ext[] = {VK_EXT_MEMORY_BUDGET_EXTENSION_NAME};
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = c->has_budget ? 1u : 0u;
  dci.ppEnabledExtensionNames = device_ext;
  check(vkCreateDevice(c->physical, &dci, nullptr, &c->device), "vkCreateDevice");
  fill_properties(*c);
  return c;
}

std::unique_ptr<Context> adopt_context(VkInstance instance, VkPhysicalDevice physical,
                                       VkDevice device, std::uint32_t family) {
  if (instance == VK_NULL_HANDLE || physical == VK_NULL_HANDLE || device == VK_NULL_HANDLE) {
    throw invalid_parameter("device", "interop handles must not be null");
  }
  auto c = std::make_unique<Context>();
  c->instance = instance;
  c->physical = physical;
  c->device = device;
  c->family = family;
  // The caller may not have enabled VK_EXT_memory_budget on its device: heap sizes only.
  c->has_budget = false;
  fill_properties(*c);
  return c;
}

}  // namespace resoct::vk::detail
