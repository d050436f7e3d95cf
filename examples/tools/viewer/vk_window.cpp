#include "viewer/vk_window.hpp"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cstring>
#include <mutex>

#include "resoct/base/error.hpp"
#include "viewer/text_panel.hpp"

namespace resoct::view {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr VkFormat kFrameFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

void check(VkResult r, const char* what) {
  if (r == VK_ERROR_OUT_OF_HOST_MEMORY || r == VK_ERROR_OUT_OF_DEVICE_MEMORY) {
    throw Error(ErrorCode::out_of_memory, std::string(what) + ": out of memory");
  }
  if (r != VK_SUCCESS) {
    throw Error(ErrorCode::device,
                std::string(what) + " failed (VkResult " + std::to_string(r) + ")");
  }
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool has_layer(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

bool has_device_extension(VkPhysicalDevice physical, const char* name) {
  std::uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &n, ext.data());
  return std::any_of(ext.begin(), ext.end(), [&](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, name) == 0;
  });
}

// A host-visible, coherent buffer kept mapped.
struct HostBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

}  // namespace

struct VkWindow::Impl {
  GLFWwindow* window = nullptr;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_props{};
  std::string name;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;   // presents
  VkCommandBuffer once = VK_NULL_HANDLE;  // read-backs
  VkFence fence = VK_NULL_HANDLE;
  bool pending = false;

  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  std::vector<VkImage> images;
  VkSemaphore acquired = VK_NULL_HANDLE;
  std::vector<VkSemaphore> rendered;  // one per swapchain image
  bool stale = true;                  // swapchain must be (re)created

  VkImage frame = VK_NULL_HANDLE;  // float RGBA copy of the frame, blit source
  VkDeviceMemory frame_memory = VK_NULL_HANDLE;
  std::uint32_t frame_w = 0, frame_h = 0;
  bool linear_blit = false;

  HostBuffer staging;   // CPU backend frames
  HostBuffer readback;  // screenshots

  // The on-screen panel (text_panel.hpp): host pixels, copied at each present into a float image
  // of its own and blitted 1:1 over the top-left corner of the swapchain image.
  std::vector<glm::vec4> panel;
  std::uint32_t panel_w = 0, panel_h = 0;
  HostBuffer panel_staging;
  VkImage panel_image = VK_NULL_HANDLE;
  VkDeviceMemory panel_memory = VK_NULL_HANDLE;
  std::uint32_t panel_image_w = 0, panel_image_h = 0;

  std::atomic<std::uint64_t> messages{0};
  mutable std::mutex log_mutex;
  std::vector<std::string> log;

  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
    auto* self = static_cast<Impl*>(user);
    self->messages.fetch_add(1);
    std::lock_guard lock(self->log_mutex);
    if (self->log.size() < 64) {
      self->log.emplace_back(data && data->pMessage ? data->pMessage : "(no message)");
    }
    return VK_FALSE;
  }

  std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags want) const {
    for (std::uint32_t i = 0; i < memory_props.memoryTypeCount; ++i) {
      if (((bits >> i) & 1u) && (memory_props.memoryTypes[i].propertyFlags & want) == want) {
        return i;
      }
    }
    throw Error(ErrorCode::device, "device: no memory type with the needed properties");
  }

  void ensure_host_buffer(HostBuffer& b, VkDeviceSize size, VkBufferUsageFlags usage) {
    if (b.size >= size) return;
    destroy_host_buffer(b);
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size;
    bci.usage = usage;
    check(vkCreateBuffer(device, &bci, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device, b.buffer, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                              VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    check(vkAllocateMemory(device, &mai, nullptr, &b.memory), "vkAllocateMemory");
    check(vkBindBufferMemory(device, b.buffer, b.memory, 0), "vkBindBufferMemory");
    check(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    b.size = size;
  }

  void destroy_host_buffer(HostBuffer& b) {
    if (b.buffer != VK_NULL_HANDLE) vkDestroyBuffer(device, b.buffer, nullptr);
    if (b.memory != VK_NULL_HANDLE) vkFreeMemory(device, b.memory, nullptr);
    b = HostBuffer{};
  }

  void ensure_frame_image(std::uint32_t w, std::uint32_t h) {
    ensure_image(frame, frame_memory, frame_w, frame_h, w, h);
  }

  // A float RGBA image that is a copy destination and a blit source, (re)made at w x h.
  void ensure_image(VkImage& image, VkDeviceMemory& memory, std::uint32_t& iw, std::uint32_t& ih,
                    std::uint32_t w, std::uint32_t h) {
    if (image != VK_NULL_HANDLE && iw == w && ih == h) return;
    destroy_image(image, memory, iw, ih);
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = kFrameFormat;
    ici.extent = {w, h, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    check(vkCreateImage(device, &ici, nullptr, &image), "vkCreateImage");
    VkMemoryRequirements req{};
    vkGetImageMemoryRequirements(device, image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(req.memoryTypeBits, 0);
    check(vkAllocateMemory(device, &mai, nullptr, &memory), "vkAllocateMemory");
    check(vkBindImageMemory(device, image, memory, 0), "vkBindImageMemory");
    iw = w;
    ih = h;
  }

  void destroy_image(VkImage& image, VkDeviceMemory& memory, std::uint32_t& w, std::uint32_t& h) {
    if (image != VK_NULL_HANDLE) vkDestroyImage(device, image, nullptr);
    if (memory != VK_NULL_HANDLE) vkFreeMemory(device, memory, nullptr);
    image = VK_NULL_HANDLE;
    memory = VK_NULL_HANDLE;
    w = h = 0;
  }

  void destroy_frame_image() {
    destroy_image(frame, frame_memory, frame_w, frame_h);
    destroy_image(panel_image, panel_memory, panel_image_w, panel_image_h);
  }

  // Records the panel's copy into the swapchain image (in TRANSFER_DST layout, just written by
  // the frame's blit).
  void record_panel(VkImage target) {
    const std::uint32_t m = kPanelMargin;
    if (panel_w == 0 || extent.width <= m || extent.height <= m) return;
    const std::uint32_t w = std::min(panel_w, extent.width - m);
    const std::uint32_t h = std::min(panel_h, extent.height - m);
    const VkDeviceSize bytes = VkDeviceSize(panel_w) * panel_h * sizeof(glm::vec4);
    ensure_host_buffer(panel_staging, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(panel_staging.mapped, panel.data(), std::size_t(bytes));
    ensure_image(panel_image, panel_memory, panel_image_w, panel_image_h, panel_w, panel_h);
    image_barrier(cmd, panel_image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {panel_w, panel_h, 1};
    vkCmdCopyBufferToImage(cmd, panel_staging.buffer, panel_image,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    image_barrier(cmd, panel_image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT);
    // The frame's blit wrote the swapchain image: this blit writes it again after it.
    image_barrier(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT);
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {std::int32_t(w), std::int32_t(h), 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.dstOffsets[0] = {std::int32_t(m), std::int32_t(m), 0};
    blit.dstOffsets[1] = {std::int32_t(m + w), std::int32_t(m + h), 1};
    vkCmdBlitImage(cmd, panel_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
  }

  void destroy_semaphores() {
    if (acquired != VK_NULL_HANDLE) vkDestroySemaphore(device, acquired, nullptr);
    acquired = VK_NULL_HANDLE;
    for (VkSemaphore s : rendered) vkDestroySemaphore(device, s, nullptr);
    rendered.clear();
  }

  // (Re)creates the swapchain for the window's framebuffer size; false while it is 0 x 0.
  bool create_swapchain() {
    vkDeviceWaitIdle(device);
    VkSurfaceCapabilitiesKHR caps{};
    check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface, &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    VkExtent2D e = caps.currentExtent;
    if (e.width == 0xFFFFFFFFu) {
      e.width = std::clamp(std::uint32_t(std::max(fw, 0)), caps.minImageExtent.width,
                           caps.maxImageExtent.width);
      e.height = std::clamp(std::uint32_t(std::max(fh, 0)), caps.minImageExtent.height,
                            caps.maxImageExtent.height);
    }
    if (e.width == 0 || e.height == 0) return false;
    if ((caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT) == 0) {
      throw Error(ErrorCode::device, "device: swapchain images cannot be transfer destinations");
    }
    std::uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &n, formats.data());
    // UNORM, not sRGB: the frame's values are display values, as its PNG holds them.
    VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (const VkSurfaceFormatKHR& f : formats) {
      VkFormatProperties fp{};
      vkGetPhysicalDeviceFormatProperties(physical, f.format, &fp);
      const bool blit = (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT) != 0;
      const bool unorm =
          f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM;
      if (blit && (unorm || chosen.format == VK_FORMAT_UNDEFINED)) chosen = f;
      if (blit && unorm) break;
    }
    if (chosen.format == VK_FORMAT_UNDEFINED) {
      throw Error(ErrorCode::device, "device: no swapchain format can be a blit destination");
    }
    vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &n, nullptr);
    std::vector<VkPresentModeKHR> modes(n);
    vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface, &n, modes.data());
    // No vsync: frame times are the renderer's (the window shows the latest frame).
    VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;
    for (VkPresentModeKHR m : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR}) {
      if (std::find(modes.begin(), modes.end(), m) != modes.end()) {
        mode = m;
        break;
      }
    }
    VkCompositeAlphaFlagBitsKHR alpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    if ((caps.supportedCompositeAlpha & alpha) == 0) {
      for (std::uint32_t bit = 1; bit != 0; bit <<= 1) {
        if (caps.supportedCompositeAlpha & bit) {
          alpha = VkCompositeAlphaFlagBitsKHR(bit);
          break;
        }
      }
    }
    VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    sci.surface = surface;
    sci.minImageCount = caps.minImageCount + 1;
    if (caps.maxImageCount != 0)
      sci.minImageCount = std::min(sci.minImageCount, caps.maxImageCount);
    sci.imageFormat = chosen.format;
    sci.imageColorSpace = chosen.colorSpace;
    sci.imageExtent = e;
    sci.imageArrayLayers = 1;
    sci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    sci.preTransform = caps.currentTransform;
    sci.compositeAlpha = alpha;
    sci.presentMode = mode;
    sci.clipped = VK_TRUE;
    sci.oldSwapchain = swapchain;
    VkSwapchainKHR fresh = VK_NULL_HANDLE;
    check(vkCreateSwapchainKHR(device, &sci, nullptr, &fresh), "vkCreateSwapchainKHR");
    if (swapchain != VK_NULL_HANDLE) vkDestroySwapchainKHR(device, swapchain, nullptr);
    swapchain = fresh;
    format = chosen.format;
    extent = e;
    vkGetSwapchainImagesKHR(device, swapchain, &n, nullptr);
    images.resize(n);
    vkGetSwapchainImagesKHR(device, swapchain, &n, images.data());
    destroy_semaphores();
    VkSemaphoreCreateInfo sem{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    check(vkCreateSemaphore(device, &sem, nullptr, &acquired), "vkCreateSemaphore");
    rendered.resize(n, VK_NULL_HANDLE);
    for (VkSemaphore& s : rendered)
      check(vkCreateSemaphore(device, &sem, nullptr, &s), "vkCreateSemaphore");
    stale = false;
    return true;
  }

  void wait_frame() {
    if (!pending) return;
    check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check(vkResetFences(device, 1, &fence), "vkResetFences");
    pending = false;
  }

  static void image_barrier(VkCommandBuffer c, VkImage image, VkImageLayout from, VkImageLayout to,
                            VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                            VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(c, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
  }

  // Copies the frame in `buffer` to the float image, blits it to the next swapchain image and
  // presents. `from_compute`: the buffer was written by a compute shader (else by the host).
  void present(VkBuffer buffer, std::uint64_t offset, std::uint32_t w, std::uint32_t h,
               bool from_compute) {
    wait_frame();
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    if (std::uint32_t(fw) != extent.width || std::uint32_t(fh) != extent.height) stale = true;
    if (stale && !create_swapchain()) return;  // minimized: nothing to show
    ensure_frame_image(w, h);
    std::uint32_t index = 0;
    VkResult r =
        vkAcquireNextImageKHR(device, swapchain, UINT64_MAX, acquired, VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
      stale = true;
      return;
    }
    if (r == VK_SUBOPTIMAL_KHR) {
      stale = true;
    } else {
      check(r, "vkAcquireNextImageKHR");
    }
    check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    const VkDeviceSize bytes = VkDeviceSize(w) * h * sizeof(glm::vec4);
    if (from_compute) {
      VkBufferMemoryBarrier b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
      b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
      b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      b.buffer = buffer;
      b.offset = offset;
      b.size = bytes;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                           VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 1, &b, 0, nullptr);
    }
    // The previous frame's blit read the float image: an execution dependency suffices.
    image_barrier(cmd, frame, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferImageCopy copy{};
    copy.bufferOffset = offset;
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {w, h, 1};
    vkCmdCopyBufferToImage(cmd, buffer, frame, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    image_barrier(cmd, frame, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT);
    // The acquire semaphore is waited at the transfer stage; this barrier chains to it.
    image_barrier(cmd, images[index], VK_IMAGE_LAYOUT_UNDEFINED,
                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {std::int32_t(w), std::int32_t(h), 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.dstOffsets[1] = {std::int32_t(extent.width), std::int32_t(extent.height), 1};
    const bool same = w == extent.width && h == extent.height;
    vkCmdBlitImage(cmd, frame, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, images[index],
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit,
                   !same && linear_blit ? VK_FILTER_LINEAR : VK_FILTER_NEAREST);
    record_panel(images[index]);
    image_barrier(cmd, images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &acquired;
    si.pWaitDstStageMask = &wait_stage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &rendered[index];
    check(vkQueueSubmit(queue, 1, &si, fence), "vkQueueSubmit");
    pending = true;
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &rendered[index];
    pi.swapchainCount = 1;
    pi.pSwapchains = &swapchain;
    pi.pImageIndices = &index;
    r = vkQueuePresentKHR(queue, &pi);
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) {
      stale = true;
    } else {
      check(r, "vkQueuePresentKHR");
    }
  }
};

VkWindow::VkWindow(GLFWwindow* window, bool validation, const std::string& device_spec)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.window = window;
  if (validation && !has_layer(kValidationLayer)) {
    throw Error(ErrorCode::device, "validation: VK_LAYER_KHRONOS_validation is not installed");
  }
  std::uint32_t glfw_count = 0;
  const char** glfw_ext = glfwGetRequiredInstanceExtensions(&glfw_count);
  if (glfw_ext == nullptr) {
    throw Error(ErrorCode::device, "window: GLFW finds no Vulkan surface support");
  }
  std::vector<const char*> ext(glfw_ext, glfw_ext + glfw_count);
  if (validation) {
    ext.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    ext.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "resoct-view";
  app.apiVersion = VK_API_VERSION_1_2;
  const VkValidationFeatureEnableEXT sync =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync;
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mci.pfnUserCallback = &Impl::on_message;
  mci.pUserData = &d;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledExtensionCount = std::uint32_t(ext.size());
  ici.ppEnabledExtensionNames = ext.data();
  const char* layers[] = {kValidationLayer};
  if (validation) {
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = layers;
    features.pNext = &mci;  // also reports instance creation and destruction
    ici.pNext = &features;
  }
  check(vkCreateInstance(&ici, nullptr, &d.instance), "vkCreateInstance");
  if (validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(d.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) throw Error(ErrorCode::device, "validation: VK_EXT_debug_utils is unavailable");
    check(create(d.instance, &mci, nullptr, &d.messenger), "vkCreateDebugUtilsMessengerEXT");
  }
  check(glfwCreateWindowSurface(d.instance, window, nullptr, &d.surface),
        "glfwCreateWindowSurface");

  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(d.instance, &count, nullptr);
  std::vector<VkPhysicalDevice> physical(count);
  vkEnumeratePhysicalDevices(d.instance, &count, physical.data());
  std::uint32_t wanted_index = ~0u;
  {
    std::uint32_t v = 0;
    const auto res =
        std::from_chars(device_spec.data(), device_spec.data() + device_spec.size(), v);
    if (!device_spec.empty() && res.ec == std::errc() &&
        res.ptr == device_spec.data() + device_spec.size()) {
      wanted_index = v;
    }
  }
  std::string seen;
  for (std::uint32_t i = 0; i < count && d.physical == VK_NULL_HANDLE; ++i) {
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(physical[i], &props);
    seen += (seen.empty() ? "" : ", ") + std::string(props.deviceName);
    if (wanted_index != ~0u
            ? i != wanted_index
            : !device_spec.empty() &&
                  lower(props.deviceName).find(lower(device_spec)) == std::string::npos) {
      continue;
    }
    if (!has_device_extension(physical[i], VK_KHR_SWAPCHAIN_EXTENSION_NAME)) continue;
    std::uint32_t qn = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical[i], &qn, nullptr);
    std::vector<VkQueueFamilyProperties> q(qn);
    vkGetPhysicalDeviceQueueFamilyProperties(physical[i], &qn, q.data());
    for (std::uint32_t f = 0; f < qn; ++f) {
      const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
      VkBool32 present = VK_FALSE;
      vkGetPhysicalDeviceSurfaceSupportKHR(physical[i], f, d.surface, &present);
      if ((q[f].queueFlags & need) == need && present) {
        d.physical = physical[i];
        d.family = f;
        d.name = props.deviceName;
        break;
      }
    }
  }
  if (d.physical == VK_NULL_HANDLE) {
    throw Error(ErrorCode::device,
                "device: no Vulkan device" +
                    (device_spec.empty() ? std::string() : " matching '" + device_spec + "'") +
                    " can present to the window from a graphics and compute queue (devices: " +
                    (seen.empty() ? "none" : seen) + ")");
  }
  vkGetPhysicalDeviceMemoryProperties(d.physical, &d.memory_props);
  VkFormatProperties fp{};
  vkGetPhysicalDeviceFormatProperties(d.physical, kFrameFormat, &fp);
  if ((fp.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT) == 0) {
    throw Error(ErrorCode::device, "device: " + d.name + " cannot blit from RGBA32F images");
  }
  d.linear_blit =
      (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = d.family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  const char* device_ext[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = 1;
  dci.ppEnabledExtensionNames = device_ext;
  check(vkCreateDevice(d.physical, &dci, nullptr, &d.device), "vkCreateDevice");
  vkGetDeviceQueue(d.device, d.family, 0, &d.queue);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = d.family;
  check(vkCreateCommandPool(d.device, &pci, nullptr, &d.pool), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = d.pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(d.device, &cai, &d.cmd), "vkAllocateCommandBuffers");
  check(vkAllocateCommandBuffers(d.device, &cai, &d.once), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(d.device, &fci, nullptr, &d.fence), "vkCreateFence");
}

VkWindow::~VkWindow() {
  Impl& d = *impl_;
  if (d.device != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(d.device);
    d.destroy_frame_image();
    d.destroy_host_buffer(d.staging);
    d.destroy_host_buffer(d.readback);
    d.destroy_host_buffer(d.panel_staging);
    d.destroy_semaphores();
    if (d.swapchain != VK_NULL_HANDLE) vkDestroySwapchainKHR(d.device, d.swapchain, nullptr);
    if (d.fence != VK_NULL_HANDLE) vkDestroyFence(d.device, d.fence, nullptr);
    if (d.pool != VK_NULL_HANDLE) vkDestroyCommandPool(d.device, d.pool, nullptr);
    vkDestroyDevice(d.device, nullptr);
  }
  if (d.surface != VK_NULL_HANDLE) vkDestroySurfaceKHR(d.instance, d.surface, nullptr);
  if (d.messenger != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(d.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(d.instance, d.messenger, nullptr);
  }
  if (d.instance != VK_NULL_HANDLE) vkDestroyInstance(d.instance, nullptr);
}

VkInstance VkWindow::instance() const noexcept {
  return impl_->instance;
}
VkPhysicalDevice VkWindow::physical() const noexcept {
  return impl_->physical;
}
VkDevice VkWindow::device() const noexcept {
  return impl_->device;
}
std::uint32_t VkWindow::queue_family() const noexcept {
  return impl_->family;
}
std::string VkWindow::device_name() const {
  return impl_->name;
}

void VkWindow::present_device(VkBuffer buffer, std::uint64_t offset, std::uint32_t width,
                              std::uint32_t height) {
  impl_->present(buffer, offset, width, height, true);
}

void VkWindow::set_panel(const glm::vec4* pixels, std::uint32_t width, std::uint32_t height) {
  Impl& d = *impl_;
  d.panel.assign(pixels, pixels + std::size_t(width) * height);
  d.panel_w = pixels == nullptr ? 0 : width;
  d.panel_h = pixels == nullptr ? 0 : height;
}

void VkWindow::present_host(const glm::vec4* pixels, std::uint32_t width, std::uint32_t height) {
  Impl& d = *impl_;
  d.wait_frame();  // the last copy may still read the staging buffer
  const VkDeviceSize bytes = VkDeviceSize(width) * height * sizeof(glm::vec4);
  d.ensure_host_buffer(d.staging, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(d.staging.mapped, pixels, std::size_t(bytes));
  d.present(d.staging.buffer, 0, width, height, false);
}

std::vector<glm::vec4> VkWindow::read_device(VkBuffer buffer, std::uint64_t offset,
                                             std::uint32_t width, std::uint32_t height) {
  Impl& d = *impl_;
  d.wait_frame();
  const VkDeviceSize bytes = VkDeviceSize(width) * height * sizeof(glm::vec4);
  d.ensure_host_buffer(d.readback, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  check(vkResetCommandBuffer(d.once, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(d.once, &begin), "vkBeginCommandBuffer");
  VkBufferMemoryBarrier b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.buffer = buffer;
  b.offset = offset;
  b.size = bytes;
  vkCmdPipelineBarrier(d.once, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       0, 0, nullptr, 1, &b, 0, nullptr);
  const VkBufferCopy region{offset, 0, bytes};
  vkCmdCopyBuffer(d.once, buffer, d.readback.buffer, 1, &region);
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(d.once, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &to_host, 0, nullptr, 0, nullptr);
  check(vkEndCommandBuffer(d.once), "vkEndCommandBuffer");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &d.once;
  check(vkQueueSubmit(d.queue, 1, &si, d.fence), "vkQueueSubmit");
  d.pending = true;
  d.wait_frame();
  std::vector<glm::vec4> out(std::size_t(width) * height);
  std::memcpy(out.data(), d.readback.mapped, std::size_t(bytes));
  return out;
}

void VkWindow::wait_frame() {
  impl_->wait_frame();
}
void VkWindow::wait_idle() {
  impl_->wait_frame();
  vkDeviceWaitIdle(impl_->device);
}

std::uint64_t VkWindow::validation_messages() const noexcept {
  return impl_->messages.load();
}
std::vector<std::string> VkWindow::validation_log() const {
  std::lock_guard lock(impl_->log_mutex);
  return impl_->log;
}

}  // namespace resoct::view
