#pragma once
// Internal: the state behind VulkanBackend, shared by its translation units
// (vulkan_backend.cpp: configure/render; backend_state.cpp: buffers, descriptors, command batch;
// frame_upload.cpp: update() and the per-frame tables through the staging ring; readback.cpp:
// results and debug reads).
//
// Every device array lives in device-local memory (MemoryUse::device). Host data reaches it only
// through the staging ring: bricks and full arrays by vkCmdCopyBuffer, page-table and octree
// deltas as (index, value) pairs applied by the scatter pass. Results come back by copying into
// one host-visible readback buffer. Commands accumulate in one batch (update() calls, then
// render()) that is submitted and waited for at the end of render(), when the ring is full, or
// before a debug read; consecutive operations are ordered by full memory barriers.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>

#include <vulkan/vulkan.h>

#include "device_memory.hpp"
#include "pipelines.hpp"
#include "scatter_pass.hpp"
#include "staging_ring.hpp"
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
  b_pages,  // the page pool
  b_directory_offsets,
  b_tf,
  b_cache,
  b_brick_requests,
  b_node_requests,
  b_used,
  b_out,
  b_stats,
  b_cache1,  // cache chunks 1..7 (chunk 0 is b_cache)
  b_cache7 = b_cache1 + 6,
  b_directory,         // the page directory (binding 21)
  b_preint,            // pre-integration tables (binding 22)
  b_step_luts,         // corrected LUTs of the step levels (binding 23)
  b_visible_subtrees,  // one word per octree node (binding 24)
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
constexpr std::uint32_t kMaxProbes = 16;  // RequestSet's default, which the CPU backend uses
constexpr std::uint32_t kStatWords = 24;
constexpr double kDistanceScale = 1048576.0;  // shaders/render.comp DISTANCE_SCALE
constexpr std::uint64_t kFenceTimeoutNs = 120ull * 1000 * 1000 * 1000;
// Staging ring size: the frame loop's brick budget plus room for deltas and tables, within
// [kMinRing, kMaxRing]; 16 MiB when the budget is unknown. Larger updates flush mid-way.
constexpr VkDeviceSize kRingHeadroom = 1ull << 20;
constexpr VkDeviceSize kMinRing = 1ull << 20;
constexpr VkDeviceSize kMaxRing = 256ull << 20;
constexpr VkDeviceSize kDefaultRing = 16ull << 20;

/// Usage of every device-local array: shader access plus transfers in both directions (uploads,
/// clears, readback).
constexpr VkBufferUsageFlags kDeviceUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                            VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                            VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

/// Byte offsets of a frame's outputs in the readback buffer.
struct ReadbackLayout {
  VkDeviceSize image = 0, brick_requests = 0, node_requests = 0, used = 0, stats = 0, total = 0;
};
ReadbackLayout readback_layout(std::size_t pixels, std::uint32_t brick_capacity,
                               std::uint32_t node_capacity, std::uint32_t cache_slots);

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
  std::unique_ptr<detail::ScatterPass> scatter;
  std::array<detail::Buffer, detail::binding_count> buf{};  // device-local
  detail::StagingRing ring;
  detail::Buffer readback;  // host-visible: frame results and debug reads
  bool descriptors_dirty = true;
  // FrameTables::step_luts_version of the step LUTs the device holds (0: none): they are re-sent
  // only when the tables' version differs (several MiB with many channels) or the buffer is new.
  std::uint64_t step_luts_on_device = 0;
  // FrameTables::visible_subtrees_version of the bits the device holds (0: unknown,
  // kZeroVisibleSubtrees: all zero, what tables without bits mean); re-sent only on change.
  static constexpr std::uint64_t kZeroVisibleSubtrees = ~std::uint64_t(0);
  std::uint64_t visible_subtrees_on_device = 0;
  bool recording = false;  // `cmd` holds an unsubmitted batch

  BackendConfig config{};
  bool configured = false;
  std::size_t voxel_bytes = 1;
  std::size_t slot_voxels = 0;
  std::uint32_t brick_capacity = 1, node_capacity = 1;
  std::uint32_t slots_per_chunk = 1;     // cache slots per cache buffer
  std::uint32_t chunks = 1;              // cache buffers in use
  std::uint64_t cache_buffer_limit = 0;  // test override of maxStorageBufferRange (0 = none)
  VkDeviceSize ring_limit = 0;           // test override of the staging ring size (0 = none)

  explicit Impl(std::unique_ptr<detail::Context> c);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  /// Where cache slot `slot` starts: its chunk's buffer and the byte offset in it.
  std::pair<VkBuffer, VkDeviceSize> slot_location(std::uint32_t slot) const;
  void release_buffers() noexcept;
  /// Makes device buffer `b` hold at least `bytes` (grows geometrically; contents are not kept).
  /// Only between batches: a recorded command may use the old buffer.
  void ensure(detail::Binding b, VkDeviceSize bytes, const char* what);
  /// Makes the readback buffer hold at least `bytes`; only between batches.
  void ensure_readback(VkDeviceSize bytes);
  void write_descriptors();

  /// Starts a batch unless one is being recorded; a new batch begins with a barrier against
  /// everything submitted before.
  void begin_batch();
  /// Submits the batch, waits for it and recycles the staging ring (no-op without a batch).
  void flush();
  /// Orders all earlier transfer/compute writes before all later transfer/compute accesses.
  void barrier();
  /// Copies `bytes` to `dst` at `offset` through the ring (split and flushed as needed).
  void stage_copy(VkBuffer dst, VkDeviceSize offset, std::span<const std::byte> bytes);
  /// Applies (index, value) pairs to a device array through the ring and the scatter pass.
  /// Indices must be in range and unique (later duplicates removed by the caller).
  void stage_scatter(detail::ScatterTarget target, std::span<const std::uint32_t> pairs,
                     std::uint32_t target_words);

  /// The specialization constants of this frame's render pipeline (see pipelines.hpp).
  detail::RenderVariant render_variant(const FrameTables& tables) const;
  /// Sizes the per-frame buffers and copies the frame tables into them.
  void upload_tables(const FrameTables& tables);
  /// Records clearing the per-frame outputs, the dispatch and the barriers around it.
  void record_render(const FrameTables& tables, VkPipeline pipeline);
  /// Where a frame puts its outputs in the readback buffer: its image (none when the image stays
  /// on the device), then requests, used bits and statistics.
  detail::ReadbackLayout readback_layout(const kernel::ResoctFrame& frame,
                                         bool image_to_host) const;
  /// Ends an unsubmitted batch without running it (configure() replaces all state anyway).
  void discard_batch() noexcept;
  /// Records copying the frame's outputs (image unless it stays on the device, statistics,
  /// request sets, used bits) into the readback buffer, followed by a barrier to host reads.
  void record_readback(const kernel::ResoctFrame& frame, bool image_to_host);
  /// Image (or its place on the device), statistics, requests and used slots of the finished
  /// frame from the readback buffer.
  void read_results(const kernel::ResoctFrame& frame, bool image_to_host,
                    FrameResult& result) const;
};

}  // namespace resoct::vk
