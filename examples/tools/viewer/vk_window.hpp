#pragma once
// resoct-view's window: a GLFW window with a Vulkan swapchain on the application's own instance
// and device, which the Vulkan backend renders on (the interop make_backend). Frames reach the
// screen without a host copy: the float RGBA buffer the renderer leaves on the device
// (FrameReport::device_image) is copied into a float image and blitted (scaled, converted to
// 8 bits) into the swapchain image. The CPU backend's frame takes the same way from a host-visible
// staging buffer.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec4.hpp>
#include <vulkan/vulkan.h>

struct GLFWwindow;

namespace resoct::view {

class VkWindow {
 public:
  /// Creates the instance (with VK_LAYER_KHRONOS_validation, synchronization validation and a
  /// messenger counting warnings and errors when `validation`), the surface of `window`, picks
  /// the device (`device`: "" = the first that can present from a graphics and compute queue, a
  /// decimal index, or a name substring) and creates it with one queue and the swapchain.
  /// Throws Error(device) naming what is missing.
  VkWindow(GLFWwindow* window, bool validation, const std::string& device);
  ~VkWindow();
  VkWindow(const VkWindow&) = delete;
  VkWindow& operator=(const VkWindow&) = delete;

  VkInstance instance() const noexcept;
  VkPhysicalDevice physical() const noexcept;
  VkDevice device() const noexcept;
  std::uint32_t queue_family() const noexcept;
  std::string device_name() const;

  /// Shows a frame left on the device: `bytes` of float RGBA (width x height) at `offset` of
  /// `buffer`, written by a compute shader on this queue family. Returns when the copy has been
  /// submitted; wait_idle_frame() waits for it.
  void present_device(VkBuffer buffer, std::uint64_t offset, std::uint32_t width,
                      std::uint32_t height);
  /// Shows a frame in host memory (width * height float RGBA pixels).
  void present_host(const glm::vec4* pixels, std::uint32_t width, std::uint32_t height);
  /// The panel (text_panel.hpp) every later present copies 1:1 over the window's top-left
  /// corner at kPanelMargin, whatever the frame's size; nullptr = no panel.
  void set_panel(const glm::vec4* pixels, std::uint32_t width, std::uint32_t height);
  /// Copies a device frame back to the host (screenshots).
  std::vector<glm::vec4> read_device(VkBuffer buffer, std::uint64_t offset, std::uint32_t width,
                                     std::uint32_t height);
  /// Waits until the last presented frame's copy is done, so that the renderer may overwrite
  /// its buffer.
  void wait_frame();
  void wait_idle();

  /// Validation warnings and errors so far (0 without validation), and the first messages.
  std::uint64_t validation_messages() const noexcept;
  std::vector<std::string> validation_log() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace resoct::view
