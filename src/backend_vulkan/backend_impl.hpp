#pragma once
// Internal: the state behind VulkanBackend, shared by its translation units
// (vulkan_backend.cpp: configure/render; backend_state.cpp: buffers, descriptors, submission;
// frame_upload.cpp: update() and the per-frame tables; readback.cpp: results and debug reads).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include <vulkan/vulkan.h>

#include "device_memory.hpp"
#include "pipelines.hpp"
#include "resoct/vulkan/vulkan_backend.hpp"
#include "timing.hpp"
#include "vk_context.hpp"

namespace resoct::vk {

namespace detail {

/// Descriptor bindings of shaders/render.comp.
enum Binding : std::uint32_t {
  b_frame,
  b_slots,
  b_levels,
  b_depths,
  b_nodes,
  b_pages,
  b_page_offsets,
  b_tf,
  b_cache,
  b_brick_requests,
  b_node_requests,
  b_used,
  b_out,
  b_stats,
  b_cache1,  // cache chunks 1..7 (chunk 0 is b_cache)
  b_cache7 = b_cache1 + 6,
  binding_count
};

constexpr std::uint32_t kCacheChunks = 8;

/// Binding of cache chunk c.
inline Binding cache_binding(std::uint32_t c) {
  return c == 0 ? b_cache : Binding(b_cache1 + c - 1);
}

/// Push constants of shaders/render.comp.
struct PushConstants {
  std::uint32_t brick_capacity, brick_log2_capacity, brick_max_probes;
  std::uint32_t node_capacity, node_log2_capacity, node_max_probes;
  std::uint32_t slots_per_chunk;
};

constexpr std::uint32_t kWorkgroup = 8;
// kernel/tf.glsl.h RESOCT_TF_LUT_SIZE (that header needs the accessors, which live in the shader).
constexpr std::size_t kTfLutSize = 1024;
constexpr std::uint32_t kMaxProbes = 16;  // RequestSet's default, which the CPU backend uses
constexpr std::uint32_t kStatWords = 24;
constexpr double kDistanceScale = 1048576.0;  // shaders/render.comp DISTANCE_SCALE
constexpr std::uint64_t kFenceTimeoutNs = 120ull * 1000 * 1000 * 1000;

}  // namespace detail

struct VulkanBackend::Impl {
  // Declared first so that it is destroyed last: everything below uses its device.
  std::unique_ptr<detail::Context> ctx;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  std::unique_ptr<detail::ComputePipelines> render_pipelines;
  std::unique_ptr<detail::GpuTimer> timer;
  std::array<detail::Buffer, detail::binding_count> buf{};
  bool descriptors_dirty = true;

  BackendConfig config{};
  bool configured = false;
  std::size_t voxel_bytes = 1;
  std::size_t slot_voxels = 0;
  std::uint32_t brick_capacity = 1, node_capacity = 1;
  std::uint32_t slots_per_chunk = 1;     // cache slots per cache buffer
  std::uint32_t chunks = 1;              // cache buffers in use
  std::uint64_t cache_buffer_limit = 0;  // test override of maxStorageBufferRange (0 = none)

  explicit Impl(std::unique_ptr<detail::Context> c);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  /// Where cache slot `slot` starts: its chunk's mapping plus the byte offset in it.
  std::byte* slot_address(std::uint32_t slot) const;
  void release_buffers() noexcept;
  /// Makes buffer `b` hold at least `bytes` (grows geometrically; contents are not kept).
  void ensure(detail::Binding b, VkDeviceSize bytes, const char* what);
  void write_descriptors();
  void submit_and_wait();

  /// The specialization constants of this frame's render pipeline (see pipelines.hpp).
  detail::RenderVariant render_variant(const FrameTables& tables) const;
  /// Sizes the per-frame buffers and copies the frame tables into them.
  void upload_tables(const FrameTables& tables);
  /// Records clearing the per-frame outputs, the dispatch and the barriers around it.
  void record_render(const kernel::ResoctFrame& frame, VkPipeline pipeline);
  /// Image, statistics, requests and used slots of the finished frame.
  void read_results(const kernel::ResoctFrame& frame, FrameResult& result) const;
};

}  // namespace resoct::vk
