// VulkanBackend: construction, configure() (buffer sizes, budget) and render() (variant,
// command recording, submission). Uploads: frame_upload.cpp; results: readback.cpp.
#include "resoct/vulkan/vulkan_backend.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <map>
#include <mutex>
#include <string>

#include "backend_impl.hpp"
#include "resoct/base/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct::vk {

using namespace detail;

namespace {

std::uint32_t log2_pow2(std::uint32_t v) {
  return std::uint32_t(std::countr_zero(v));
}

}  // namespace

std::unique_ptr<Backend> make_backend(const BackendOptions& options) {
  return std::make_unique<VulkanBackend>(options);
}

std::unique_ptr<Backend> make_backend(VkInstance instance, VkPhysicalDevice physical,
                                      VkDevice device, std::uint32_t queue_family) {
  return std::make_unique<VulkanBackend>(instance, physical, device, queue_family);
}

void register_backend() {
  static std::once_flag once;
  std::call_once(once, [] {
    resoct::register_backend("vulkan", [](const BackendOptions& o) { return vk::make_backend(o); });
  });
}

VulkanBackend::VulkanBackend(const BackendOptions& options)
    : impl_(std::make_unique<Impl>(detail::create_context(options))) {}

VulkanBackend::VulkanBackend(VkInstance instance, VkPhysicalDevice physical, VkDevice device,
                             std::uint32_t queue_family)
    : impl_(
          std::make_unique<Impl>(detail::adopt_context(instance, physical, device, queue_family))) {
}

VulkanBackend::~VulkanBackend() = default;

std::string VulkanBackend::device_name() const {
  return impl_->ctx->props.deviceName;
}

std::uint32_t VulkanBackend::loop_iteration_limit() const noexcept {
  return impl_->ctx->loop_limit;
}

std::uint64_t VulkanBackend::validation_messages() const noexcept {
  return impl_->ctx->messages.load(std::memory_order_relaxed);
}

std::vector<std::string> VulkanBackend::validation_log() const {
  std::lock_guard lock(impl_->ctx->log_mutex);
  return impl_->ctx->log;
}

void VulkanBackend::configure(const BackendConfig& config) {
  Impl& m = *impl_;
  const glm::uvec3 p = config.padded_brick;
  if (p.x == 0 || p.y == 0 || p.z == 0) throw invalid_parameter("config", "padded_brick is 0");
  const std::uint64_t slot_voxels = std::uint64_t(p.x) * p.y * p.z;
  const std::uint64_t vb = voxel_size(config.voxel_type);
  // The shader addresses the cache with 32-bit voxel indices.
  if (config.cache_slots > 0 && slot_voxels > (std::uint64_t(1) << 32) / config.cache_slots) {
    throw invalid_parameter("config", "cache pool exceeds 2^32 voxels");
  }
  if (config.node_words > (std::uint64_t(1) << 32)) {
    throw invalid_parameter("config", "node_words exceeds 2^32");
  }
  if (config.brick_request_capacity == 0 || config.brick_request_capacity > (1u << 28) ||
      config.node_request_capacity == 0 || config.node_request_capacity > (1u << 28)) {
    throw invalid_parameter("config", "request capacities must be 1..2^28");
  }
  const std::uint32_t brick_cap = std::bit_ceil(config.brick_request_capacity);
  const std::uint32_t node_cap = std::bit_ceil(config.node_request_capacity);
  // Whole bricks per cache buffer, so that no brick straddles two buffers.
  std::uint64_t range = m.ctx->props.limits.maxStorageBufferRange & ~3u;
  if (m.cache_buffer_limit != 0) range = std::min(range, m.cache_buffer_limit);
  const std::uint64_t brick_bytes = slot_voxels * vb;
  if (brick_bytes > range) {
    throw Error(ErrorCode::out_of_memory, "vulkan: one brick of " + std::to_string(brick_bytes) +
                                              " bytes exceeds maxStorageBufferRange");
  }
  const std::uint32_t slots_per_chunk =
      std::uint32_t(std::min<std::uint64_t>(range / brick_bytes, std::max(config.cache_slots, 1u)));
  const std::uint32_t chunks = (config.cache_slots + slots_per_chunk - 1) / slots_per_chunk;
  if (chunks > kCacheChunks) {
    throw Error(ErrorCode::out_of_memory,
                "vulkan: brick cache of " + std::to_string(brick_bytes * config.cache_slots) +
                    " bytes needs more than " + std::to_string(kCacheChunks) + " buffers of " +
                    "maxStorageBufferRange (" + std::to_string(range) + " bytes)");
  }
  const std::uint64_t cache_bytes =
      (std::uint64_t(config.cache_slots) * slot_voxels * vb + 3) & ~3ull;
  check_page_table_config(config);
  const std::array<std::pair<std::uint64_t, const char*>, 7> sizes = {{
      {std::uint64_t(config.page_pool_blocks) * kernel::RESOCT_PAGE_BLOCK_ENTRIES * 4,
       "page pool (RendererOptions::page_pool_blocks)"},
      {(std::uint64_t(config.page_tables) + 1) * 4, "page directory offsets"},
      {config.node_words * 4, "octree"},
      {std::uint64_t(brick_cap) * 8, "brick request set"},
      {std::uint64_t(node_cap) * 8, "node request set"},
      {(std::uint64_t(config.cache_slots) + 31) / 32 * 4, "used-slot bitmap"},
      {std::max<std::uint64_t>(config.directory_entries, 1) * 4, "page directory"},
  }};
  std::uint64_t total = cache_bytes;
  for (const auto& [bytes, what] : sizes) {
    if (bytes > m.ctx->props.limits.maxStorageBufferRange) {
      throw Error(ErrorCode::out_of_memory, std::string("vulkan: ") + what + " of " +
                                                std::to_string(bytes) +
                                                " bytes exceeds maxStorageBufferRange");
    }
    total += bytes;
  }
  // Staging ring: the frame loop's upload budget plus headroom for deltas and tables.
  VkDeviceSize ring_bytes =
      config.upload_bytes_per_frame == 0
          ? kDefaultRing
          : std::clamp<VkDeviceSize>(config.upload_bytes_per_frame + kRingHeadroom, kMinRing,
                                     kMaxRing);
  if (m.ring_limit != 0) ring_bytes = std::min(ring_bytes, m.ring_limit);
  ring_bytes = std::min<VkDeviceSize>(ring_bytes, m.ctx->props.limits.maxStorageBufferRange & ~15u);
  const VkDeviceSize readback_bytes =
      readback_layout(0, brick_cap, node_cap, config.cache_slots).total;
  std::map<std::uint32_t, VkDeviceSize> plan;
  plan[heap_of(*m.ctx, MemoryUse::device)] += total;
  plan[heap_of(*m.ctx, MemoryUse::upload)] += ring_bytes;
  plan[heap_of(*m.ctx, MemoryUse::readback)] += readback_bytes;

  m.configured = false;
  m.discard_batch();
  check(vkDeviceWaitIdle(m.ctx->device), "vkDeviceWaitIdle");
  m.release_buffers();
  check_budget(*m.ctx, plan);
  m.config = config;
  m.voxel_bytes = std::size_t(vb);
  m.slot_voxels = std::size_t(slot_voxels);
  m.brick_capacity = brick_cap;
  m.node_capacity = node_cap;
  m.slots_per_chunk = slots_per_chunk;
  m.chunks = std::max(chunks, 1u);
  for (std::uint32_t c = 0; c < kCacheChunks; ++c) {
    const std::uint32_t first = std::min(config.cache_slots, c * slots_per_chunk);
    const std::uint32_t n = std::min(config.cache_slots - first, slots_per_chunk);
    m.ensure(cache_binding(c), (std::uint64_t(n) * brick_bytes + 3) & ~3ull, "brick cache");
  }
  const Binding order[] = {b_pages, b_directory_offsets, b_nodes, b_brick_requests, b_node_requests,
                           b_used,  b_directory};
  for (std::size_t i = 0; i < sizes.size(); ++i)
    m.ensure(order[i], sizes[i].first, sizes[i].second);
  m.ensure(b_stats, kStatWords * 4, "statistics");
  // ResoctFrame followed by ResoctFxFrame (render.comp's FrameBuf).
  m.ensure(b_frame, sizeof(kernel::ResoctFrame) + sizeof(kernel::ResoctFxFrame), "frame constants");
  m.ring.create(*m.ctx, ring_bytes);
  m.ensure_readback(readback_bytes);
  m.scatter->bind(ScatterTarget::pages, m.ring.buffer(), m.ring.capacity(), m.buf[b_pages].buffer,
                  m.buf[b_pages].size);
  m.scatter->bind(ScatterTarget::directory, m.ring.buffer(), m.ring.capacity(),
                  m.buf[b_directory].buffer, m.buf[b_directory].size);
  m.scatter->bind(ScatterTarget::nodes, m.ring.buffer(), m.ring.capacity(), m.buf[b_nodes].buffer,
                  m.buf[b_nodes].size);
  // All state reads as zero after configure().
  m.begin_batch();
  for (const Buffer& b : m.buf) {
    if (b.buffer != VK_NULL_HANDLE) vkCmdFillBuffer(m.cmd, b.buffer, 0, VK_WHOLE_SIZE, 0);
  }
  m.flush();
  // The pipeline is built by the first render(): compiling the kernel takes seconds on CPU
  // devices, and a configuration that is only updated never needs it.
  m.step_luts_on_device = 0;
  m.visible_subtrees_on_device = 0;
  m.configured = true;
}

RenderVariant VulkanBackend::Impl::render_variant(const FrameTables& tables) const {
  RenderVariant v;
  v.voxel_type = std::uint32_t(config.voxel_type);
  v.padded_x = config.padded_brick.x;
  v.padded_y = config.padded_brick.y;
  v.padded_z = config.padded_brick.z;
  v.cache_chunks = chunks;
  v.workgroup_x = kWorkgroup;
  v.workgroup_y = kWorkgroup;
  v.effects = tables.fx.effects & (kernel::RESOCT_EFFECT_MASKS - 1u);
  return v;
}

void VulkanBackend::Impl::record_render(const FrameTables& tables, VkPipeline pipeline) {
  const kernel::ResoctFrame& frame = tables.frame;
  begin_batch();
  // Table copies and delta scatters of this batch are done before the clears and the dispatch.
  barrier();
  // Clear the per-frame outputs on the device: request keys to "free", counts and bits to 0.
  vkCmdFillBuffer(cmd, buf[b_brick_requests].buffer, 0, VkDeviceSize(brick_capacity) * 4,
                  kernel::RESOCT_REQUEST_KEY_NONE);
  vkCmdFillBuffer(cmd, buf[b_brick_requests].buffer, VkDeviceSize(brick_capacity) * 4,
                  VkDeviceSize(brick_capacity) * 4, 0);
  vkCmdFillBuffer(cmd, buf[b_node_requests].buffer, 0, VkDeviceSize(node_capacity) * 4,
                  kernel::RESOCT_REQUEST_KEY_NONE);
  vkCmdFillBuffer(cmd, buf[b_node_requests].buffer, VkDeviceSize(node_capacity) * 4,
                  VkDeviceSize(node_capacity) * 4, 0);
  vkCmdFillBuffer(cmd, buf[b_used].buffer, 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(cmd, buf[b_stats].buffer, 0, VK_WHOLE_SIZE, 0);
  barrier();
  timer->begin(cmd);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout, 0, 1, &set, 0,
                          nullptr);
  const PushConstants pc{
      brick_capacity, log2_pow2(brick_capacity), std::min(kMaxProbes, brick_capacity),
      node_capacity,  log2_pow2(node_capacity),  std::min(kMaxProbes, node_capacity),
      slots_per_chunk};
  vkCmdPushConstants(cmd, pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
  vkCmdDispatch(cmd, (frame.width + kWorkgroup - 1) / kWorkgroup,
                (frame.height + kWorkgroup - 1) / kWorkgroup, 1);
  timer->end(cmd);
  record_readback(frame, tables.image_to_host);
}

void VulkanBackend::render(const FrameTables& tables, FrameResult& result) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  if (!m.configured) throw invalid_parameter("tables", "backend is not configured");
  check_frame_tables(tables, m.config);
  m.ensure_readback(m.readback_layout(tables.frame, tables.image_to_host).total);
  m.upload_tables(tables);
  m.write_descriptors();
  // Compiling the kernel is slow (seconds on lavapipe): the cache compiles each variant once.
  const VkPipeline pipeline = m.render_pipelines->get(m.render_variant(tables));
  m.step_luts_on_device = 0;  // until the frame that sends them has run
  m.visible_subtrees_on_device = 0;
  m.record_render(tables, pipeline);
  m.flush();
  m.step_luts_on_device = tables.step_luts_version;
  m.visible_subtrees_on_device = tables.visible_subtrees.empty() ? Impl::kZeroVisibleSubtrees
                                                                 : tables.visible_subtrees_version;
  invalidate(*m.ctx, m.readback);
  m.read_results(tables.frame, tables.image_to_host, result);
  result.stats.ms_render =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void VulkanBackend::debug_limit_cache_buffer(std::uint64_t bytes) noexcept {
  impl_->cache_buffer_limit = bytes;
}

void VulkanBackend::debug_limit_staging_ring(std::uint64_t bytes) noexcept {
  impl_->ring_limit = bytes;
}

std::size_t VulkanBackend::debug_pipeline_count() const noexcept {
  return impl_->render_pipelines->size();
}

}  // namespace resoct::vk
