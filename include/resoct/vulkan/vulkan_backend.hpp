#pragma once
/// \file
/// The Vulkan compute backend: the single-source traversal kernel compiled to SPIR-V
/// (src/backend_vulkan/shaders/render.comp), one invocation per pixel. Device state lives in
/// device-local storage buffers, written only through a host-visible staging ring sized from
/// BackendConfig::upload_bytes_per_frame (bricks by buffer copies, page-table and octree deltas
/// as (index, value) pairs applied by a scatter shader). The voxel cache is up to 8 buffers of
/// whole bricks (one buffer may not exceed maxStorageBufferRange) holding voxels of the configured
/// type filtered in the shader exactly like the CPU backend, so the CPU backend is its test
/// oracle. docs/vulkan-backend.md has the details.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "resoct/backend/backend.hpp"

namespace resoct::vk {

/// A Vulkan backend object with its own instance and device, for Renderer(source, backend,
/// options): see VulkanBackend(const BackendOptions&) for `options` and the errors.
std::unique_ptr<Backend> make_backend(const BackendOptions& options = {});
/// A Vulkan backend object on an application's instance and device (the interop constructor
/// VulkanBackend(instance, physical, device, queue_family); the handles stay the caller's and
/// must outlive the Renderer).
std::unique_ptr<Backend> make_backend(VkInstance instance, VkPhysicalDevice physical,
                                      VkDevice device, std::uint32_t queue_family);

/// The VkBuffer of an image a frame left on the device (FrameReport::device_image with output
/// FrameOutput::device; VK_NULL_HANDLE when its handle is 0), and the inverse.
VkBuffer buffer_of(const DeviceImage& image) noexcept;
std::uint64_t handle_of(VkBuffer buffer) noexcept;

/// Registers the backend under the name "vulkan" (idempotent, thread-safe), for name-based
/// creation (RendererOptions::backend). The factory honours BackendOptions::device and
/// ::validation.
void register_backend();

/// Device arrays a test can read back (debug_read()).
/// `pages` is the page pool, `directory` and `directory_offsets` the sparse page table's
/// directory (include/resoct/engine/page_table.hpp).
enum class DeviceArray : std::uint8_t { cache, pages, directory, directory_offsets, nodes };

/// Not thread-safe: one Renderer drives it from one thread. update() copies its input into the
/// staging ring and render() waits for the device, so the host may reuse its spans as soon as a
/// call returns.
class VulkanBackend : public Backend {
 public:
  /// Creates its own instance and device. `options.device`: a decimal index into
  /// list_devices() or a case-insensitive name substring ("" = the best device with a compute
  /// queue: discrete, integrated, virtual, then CPU). `options.validation` (or the environment
  /// variable RESOCT_VK_VALIDATION=1) enables VK_LAYER_KHRONOS_validation and records its
  /// warnings and errors. Throws Error(device) naming "device" when no device matches or the
  /// device cannot be created, Error(out_of_memory) when memory runs out.
  explicit VulkanBackend(const BackendOptions& options = {});
  /// Interop: renders with an application's device. The handles stay owned by the caller and
  /// must outlive the backend; `queue_family` must support compute; queue 0 of it is used
  /// (externally synchronized: do not submit to it concurrently with this backend's calls).
  VulkanBackend(VkInstance instance, VkPhysicalDevice physical, VkDevice device,
                std::uint32_t queue_family);
  ~VulkanBackend() override;
  VulkanBackend(const VulkanBackend&) = delete;
  VulkanBackend& operator=(const VulkanBackend&) = delete;

  std::string_view name() const noexcept override { return "vulkan"; }
  /// As CpuBackend::configure; additionally Error(out_of_memory) when a buffer exceeds the
  /// device's storage-buffer range, its heap, or the VK_EXT_memory_budget budget.
  void configure(const BackendConfig& config) override;
  /// As CpuBackend::update (same checks, same messages naming "update"). Records the transfers;
  /// they run with the next render() or debug_read(), or earlier when the staging ring is full.
  /// The spans are copied into the ring before returning, so the host may reuse them.
  void update(const FrameUpdate& update) override;
  /// As CpuBackend::render; ms_device is measured with timestamp queries (0 when the queue has
  /// no timestamps). Error(device) on device loss.
  void render(const FrameTables& tables, FrameResult& result) override;

  /// Name of the physical device in use.
  std::string device_name() const;
  /// Loop back-edges one shader invocation may take before the driver ends all its loops, or 0
  /// when the driver has no such limit. Mesa's lavapipe has one (65535, counted over every loop
  /// of the kernel: roughly 2000 march iterations of a simple ray); a ray it cuts short is
  /// counted in BackendStats::cap_hits, like a ray stopped by max_iterations, never silently
  /// rendered short.
  std::uint32_t loop_iteration_limit() const noexcept;
  /// Validation-layer warnings and errors recorded so far (0 when validation is off).
  std::uint64_t validation_messages() const noexcept;
  /// The recorded validation messages (the first 64).
  std::vector<std::string> validation_log() const;
  /// Test support: copies a device array back to the host (cache as bytes, others as uint32
  /// words packed little-endian into bytes). Waits for the device.
  std::vector<std::byte> debug_read(DeviceArray array) const;

  /// Test support: caps the bytes of each cache buffer (default and upper bound:
  /// maxStorageBufferRange) from the next configure() on, so that tests exercise a cache split
  /// over several buffers. 0 restores the default.
  void debug_limit_cache_buffer(std::uint64_t bytes) noexcept;
  /// Test support: caps the staging ring (bytes) from the next configure() on, so that tests
  /// exercise updates split over several submissions. 0 restores the default.
  void debug_limit_staging_ring(std::uint64_t bytes) noexcept;
  /// Test support: render pipelines compiled so far. Pipelines are cached per distinct set of
  /// specialization constants (voxel type, padded brick, cache buffers, ...), so reconfiguring
  /// back to an earlier configuration compiles nothing.
  std::size_t debug_pipeline_count() const noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace resoct::vk
