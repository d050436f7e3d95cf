#include "resoct/vulkan/vulkan_backend.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstring>
#include <mutex>

#include "resoct/error.hpp"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct_render_spv.h"
#include "vk_context.hpp"

namespace resoct::vk {

namespace {

using detail::Buffer;
using detail::check;

// Descriptor bindings of shaders/render.comp.
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

// Binding of cache chunk c.
Binding cache_binding(std::uint32_t c) {
  return c == 0 ? b_cache : Binding(b_cache1 + c - 1);
}

struct PushConstants {
  std::uint32_t brick_capacity, brick_log2_capacity, brick_max_probes;
  std::uint32_t node_capacity, node_log2_capacity, node_max_probes;
  std::uint32_t slots_per_chunk;
};

constexpr std::uint32_t kWorkgroup = 8;
// kernel/tf.glsl.h RESOCT_TF_LUT_SIZE (that header needs the accessors, which live in the shader).
constexpr std::size_t kTfLutSize = 1024;
constexpr std::uint32_t kMaxProbes = 16;  // RequestSet's default, which the CPU backend uses
constexpr std::uint32_t kStatWords = 20;
constexpr double kDistanceScale = 1048576.0;  // shaders/render.comp DISTANCE_SCALE
constexpr std::uint64_t kFenceTimeoutNs = 120ull * 1000 * 1000 * 1000;

std::uint32_t log2_pow2(std::uint32_t v) {
  return std::uint32_t(std::countr_zero(v));
}

}  // namespace

struct VulkanBackend::Impl {
  std::unique_ptr<detail::Context> ctx;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkShaderModule shader = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;
  std::array<Buffer, binding_count> buf{};
  bool descriptors_dirty = true;
  std::array<std::uint32_t, 7> pipeline_key{};

  BackendConfig config{};
  bool configured = false;
  std::size_t voxel_bytes = 1;
  std::size_t slot_voxels = 0;
  std::uint32_t brick_capacity = 1, node_capacity = 1;
  std::uint32_t slots_per_chunk = 1;     // cache slots per cache buffer
  std::uint32_t chunks = 1;              // cache buffers in use
  std::uint64_t cache_buffer_limit = 0;  // test override of maxStorageBufferRange (0 = none)

  /// Where cache slot `slot` starts: its chunk's mapping plus the byte offset in it.
  std::byte* slot_address(std::uint32_t slot) const {
    const std::uint32_t c = slot / slots_per_chunk;
    return static_cast<std::byte*>(buf[cache_binding(c)].mapped) +
           std::size_t(slot - c * slots_per_chunk) * slot_voxels * voxel_bytes;
  }

  explicit Impl(std::unique_ptr<detail::Context> c);
  ~Impl();
  void release_buffers() noexcept;
  void ensure(Binding b, VkDeviceSize bytes, const char* what);
  void write_descriptors();
  void build_pipeline();
  void check_tables(const FrameTables& t) const;
  void submit_and_wait();
};

VulkanBackend::Impl::Impl(std::unique_ptr<detail::Context> c) : ctx(std::move(c)) {
  VkDevice dev = ctx->device;
  std::array<VkDescriptorSetLayoutBinding, binding_count> bindings{};
  for (std::uint32_t i = 0; i < binding_count; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = binding_count;
  lci.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(dev, &lci, nullptr, &set_layout),
        "vkCreateDescriptorSetLayout");
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &set_layout;
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &range;
  check(vkCreatePipelineLayout(dev, &plci, nullptr, &pipeline_layout), "vkCreatePipelineLayout");
  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, binding_count};
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 1;
  dpci.poolSizeCount = 1;
  dpci.pPoolSizes = &ps;
  check(vkCreateDescriptorPool(dev, &dpci, nullptr, &pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = pool;
  dsai.descriptorSetCount = 1;
  dsai.pSetLayouts = &set_layout;
  check(vkAllocateDescriptorSets(dev, &dsai, &set), "vkAllocateDescriptorSets");
  VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smci.codeSize = sizeof(resoct_render_spv);
  smci.pCode = resoct_render_spv;
  check(vkCreateShaderModule(dev, &smci, nullptr, &shader), "vkCreateShaderModule");
  VkCommandPoolCreateInfo cpci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cpci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cpci.queueFamilyIndex = ctx->family;
  check(vkCreateCommandPool(dev, &cpci, nullptr, &command_pool), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cbai.commandPool = command_pool;
  cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbai.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(dev, &cbai, &cmd), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(dev, &fci, nullptr, &fence), "vkCreateFence");
  if (ctx->timestamp_bits > 0) {
    VkQueryPoolCreateInfo qpci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qpci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qpci.queryCount = 2;
    check(vkCreateQueryPool(dev, &qpci, nullptr, &queries), "vkCreateQueryPool");
  }
}

VulkanBackend::Impl::~Impl() {
  VkDevice dev = ctx->device;
  vkDeviceWaitIdle(dev);
  release_buffers();
  if (queries) vkDestroyQueryPool(dev, queries, nullptr);
  if (fence) vkDestroyFence(dev, fence, nullptr);
  if (command_pool) vkDestroyCommandPool(dev, command_pool, nullptr);
  if (pipeline) vkDestroyPipeline(dev, pipeline, nullptr);
  if (shader) vkDestroyShaderModule(dev, shader, nullptr);
  if (pool) vkDestroyDescriptorPool(dev, pool, nullptr);
  if (pipeline_layout) vkDestroyPipelineLayout(dev, pipeline_layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(dev, set_layout, nullptr);
}

void VulkanBackend::Impl::release_buffers() noexcept {
  for (Buffer& b : buf) detail::destroy_buffer(*ctx, b);
  descriptors_dirty = true;
}

void VulkanBackend::Impl::ensure(Binding b, VkDeviceSize bytes, const char* what) {
  if (buf[b].buffer != VK_NULL_HANDLE && buf[b].size >= bytes) return;
  if (bytes > ctx->props.limits.maxStorageBufferRange) {
    throw Error(ErrorCode::out_of_memory, std::string("vulkan: ") + what + " of " +
                                              std::to_string(bytes) +
                                              " bytes exceeds maxStorageBufferRange");
  }
  // Grow geometrically so that slowly growing tables do not reallocate every frame.
  const VkDeviceSize size = std::max<VkDeviceSize>(bytes, buf[b].size * 2);
  detail::destroy_buffer(*ctx, buf[b]);
  buf[b] = detail::create_buffer(
      *ctx, std::min<VkDeviceSize>(size, ctx->props.limits.maxStorageBufferRange), what);
  descriptors_dirty = true;
}

void VulkanBackend::Impl::write_descriptors() {
  if (!descriptors_dirty) return;
  std::array<VkDescriptorBufferInfo, binding_count> info{};
  std::array<VkWriteDescriptorSet, binding_count> writes{};
  for (std::uint32_t i = 0; i < binding_count; ++i) {
    info[i] = {buf[i].buffer, 0, VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &info[i];
  }
  vkUpdateDescriptorSets(ctx->device, binding_count, writes.data(), 0, nullptr);
  descriptors_dirty = false;
}

void VulkanBackend::Impl::build_pipeline() {
  // Specialization: voxel type and padded brick size are constants of the cache addressing.
  const std::array<std::uint32_t, 7> values = {std::uint32_t(config.voxel_type),
                                               config.padded_brick.x,
                                               config.padded_brick.y,
                                               config.padded_brick.z,
                                               chunks,
                                               kWorkgroup,
                                               kWorkgroup};
  const std::array<VkSpecializationMapEntry, 7> entries = {
      {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}, {3, 12, 4}, {4, 16, 4}, {10, 20, 4}, {11, 24, 4}}};
  VkSpecializationInfo si{};
  si.mapEntryCount = std::uint32_t(entries.size());
  si.pMapEntries = entries.data();
  si.dataSize = sizeof(values);
  si.pData = values.data();
  VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cpci.stage.module = shader;
  cpci.stage.pName = "main";
  cpci.stage.pSpecializationInfo = &si;
  cpci.layout = pipeline_layout;
  // Compiling the kernel is slow (seconds on lavapipe): reuse the pipeline while the
  // specialization is unchanged.
  if (pipeline != VK_NULL_HANDLE && values == pipeline_key) return;
  if (pipeline) vkDestroyPipeline(ctx->device, pipeline, nullptr);
  pipeline = VK_NULL_HANDLE;
  check(vkCreateComputePipelines(ctx->device, VK_NULL_HANDLE, 1, &cpci, nullptr, &pipeline),
        "vkCreateComputePipelines");
  pipeline_key = values;
}

void VulkanBackend::Impl::submit_and_wait() {
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  check(vkResetFences(ctx->device, 1, &fence), "vkResetFences");
  check(vkQueueSubmit(ctx->queue, 1, &si, fence), "vkQueueSubmit");
  const VkResult r = vkWaitForFences(ctx->device, 1, &fence, VK_TRUE, kFenceTimeoutNs);
  if (r == VK_TIMEOUT)
    throw Error(ErrorCode::device, "vulkan: device: frame did not finish in 120 s");
  check(r, "vkWaitForFences");
}

void VulkanBackend::Impl::check_tables(const FrameTables& t) const {
  if (!configured) throw invalid_parameter("tables", "backend is not configured");
  check_frame_tables(t, config);
}

void register_backend() {
  static std::once_flag once;
  std::call_once(once, [] {
    resoct::register_backend("vulkan", [](const BackendOptions& o) -> std::unique_ptr<Backend> {
      return std::make_unique<VulkanBackend>(o);
    });
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
  const std::array<std::pair<std::uint64_t, const char*>, 6> sizes = {{
      {std::uint64_t(config.page_entries) * 4, "page table"},
      {(std::uint64_t(config.page_tables) + 1) * 4, "page table offsets"},
      {config.node_words * 4, "octree"},
      {std::uint64_t(brick_cap) * 8, "brick request set"},
      {std::uint64_t(node_cap) * 8, "node request set"},
      {(std::uint64_t(config.cache_slots) + 31) / 32 * 4, "used-slot bitmap"},
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
  m.configured = false;
  check(vkDeviceWaitIdle(m.ctx->device), "vkDeviceWaitIdle");
  m.release_buffers();
  detail::check_budget(*m.ctx, total);
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
  const Binding order[] = {b_pages,          b_page_offsets,  b_nodes,
                           b_brick_requests, b_node_requests, b_used};
  for (std::size_t i = 0; i < sizes.size(); ++i)
    m.ensure(order[i], sizes[i].first, sizes[i].second);
  m.ensure(b_stats, kStatWords * 4, "statistics");
  m.ensure(b_frame, sizeof(kernel::ResoctFrame), "frame constants");
  // The pipeline is built by the first render(): compiling the kernel takes seconds on CPU
  // devices, and a configuration that is only updated never needs it.
  m.configured = true;
}

void VulkanBackend::update(const FrameUpdate& u) {
  Impl& m = *impl_;
  if (!m.configured) throw invalid_parameter("update", "backend is not configured");
  const std::size_t brick_bytes = m.slot_voxels * m.voxel_bytes;
  auto* pages = static_cast<std::uint32_t*>(m.buf[b_pages].mapped);
  auto* offsets = static_cast<std::uint32_t*>(m.buf[b_page_offsets].mapped);
  auto* nodes = static_cast<std::uint32_t*>(m.buf[b_nodes].mapped);
  const std::size_t page_count = m.config.page_entries;
  const std::size_t node_count = std::size_t(m.config.node_words);
  // The device is idle between calls (render() waits), so writing through the mapping is the
  // scatter; host-coherent memory makes it visible to the next submission.
  for (const BrickUpload& b : u.bricks) {
    if (b.cache_slot >= m.config.cache_slots) {
      throw invalid_parameter("update", "cache slot " + std::to_string(b.cache_slot) +
                                            " outside the configured " +
                                            std::to_string(m.config.cache_slots));
    }
    if (b.voxels.size() != brick_bytes) {
      throw invalid_parameter("update", "brick of " + std::to_string(b.voxels.size()) +
                                            " bytes, expected " + std::to_string(brick_bytes));
    }
    std::memcpy(m.slot_address(b.cache_slot), b.voxels.data(), brick_bytes);
  }
  if (u.pages_full) {
    if (u.all_pages.size() != page_count) {
      throw invalid_parameter("update", "full page table of " + std::to_string(u.all_pages.size()) +
                                            " entries, expected " + std::to_string(page_count));
    }
    if (u.page_table_offsets.size() != std::size_t(m.config.page_tables) + 1u) {
      throw invalid_parameter("update", "page_table_offsets has the wrong size");
    }
    for (std::uint32_t o : u.page_table_offsets) {
      if (o > page_count) throw invalid_parameter("update", "page table offset out of range");
    }
    std::copy(u.all_pages.begin(), u.all_pages.end(), pages);
    std::copy(u.page_table_offsets.begin(), u.page_table_offsets.end(), offsets);
  }
  for (const PageDelta& d : u.page_deltas) {
    if (d.index >= page_count) throw invalid_parameter("update", "page delta out of range");
    pages[d.index] = d.value;
  }
  if (u.nodes_full) {
    if (u.all_nodes.size() != node_count) {
      throw invalid_parameter("update", "full octree of " + std::to_string(u.all_nodes.size()) +
                                            " words, expected " + std::to_string(node_count));
    }
    std::copy(u.all_nodes.begin(), u.all_nodes.end(), nodes);
  }
  for (const OctreeWordDelta& d : u.node_deltas) {
    if (d.index >= node_count) throw invalid_parameter("update", "octree delta out of range");
    nodes[d.index] = d.value;
  }
}

void VulkanBackend::render(const FrameTables& tables, FrameResult& result) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  m.check_tables(tables);
  const kernel::ResoctFrame& frame = tables.frame;
  const std::size_t pixels = std::size_t(frame.width) * frame.height;
  m.ensure(b_slots, std::max<std::size_t>(tables.slots.size(), 1) * sizeof(kernel::ResoctSlotInfo),
           "slot table");
  m.ensure(b_levels, tables.levels.size() * sizeof(kernel::ResoctLevelInfo), "level table");
  m.ensure(b_depths, tables.depths.size() * sizeof(kernel::ResoctDepthInfo), "depth table");
  m.ensure(b_tf, std::max<std::size_t>(tables.tf_luts.size(), 1) * sizeof(glm::vec4),
           "transfer functions");
  m.ensure(b_out, pixels * sizeof(glm::vec4), "output image");
  m.write_descriptors();
  m.build_pipeline();
  std::memcpy(m.buf[b_frame].mapped, &frame, sizeof(frame));
  std::memcpy(m.buf[b_slots].mapped, tables.slots.data(),
              tables.slots.size() * sizeof(tables.slots[0]));
  std::memcpy(m.buf[b_levels].mapped, tables.levels.data(),
              tables.levels.size() * sizeof(tables.levels[0]));
  std::memcpy(m.buf[b_depths].mapped, tables.depths.data(),
              tables.depths.size() * sizeof(tables.depths[0]));
  std::memcpy(m.buf[b_tf].mapped, tables.tf_luts.data(), tables.tf_luts.size() * sizeof(glm::vec4));

  check(vkResetCommandBuffer(m.cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(m.cmd, &begin), "vkBeginCommandBuffer");
  // Clear the per-frame outputs on the device: request keys to "free", counts and bits to 0.
  vkCmdFillBuffer(m.cmd, m.buf[b_brick_requests].buffer, 0, VkDeviceSize(m.brick_capacity) * 4,
                  kernel::RESOCT_REQUEST_KEY_NONE);
  vkCmdFillBuffer(m.cmd, m.buf[b_brick_requests].buffer, VkDeviceSize(m.brick_capacity) * 4,
                  VkDeviceSize(m.brick_capacity) * 4, 0);
  vkCmdFillBuffer(m.cmd, m.buf[b_node_requests].buffer, 0, VkDeviceSize(m.node_capacity) * 4,
                  kernel::RESOCT_REQUEST_KEY_NONE);
  vkCmdFillBuffer(m.cmd, m.buf[b_node_requests].buffer, VkDeviceSize(m.node_capacity) * 4,
                  VkDeviceSize(m.node_capacity) * 4, 0);
  vkCmdFillBuffer(m.cmd, m.buf[b_used].buffer, 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(m.cmd, m.buf[b_stats].buffer, 0, VK_WHOLE_SIZE, 0);
  VkMemoryBarrier to_shader{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_shader.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT;
  to_shader.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(m.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &to_shader, 0, nullptr, 0,
                       nullptr);
  if (m.queries) {
    vkCmdResetQueryPool(m.cmd, m.queries, 0, 2);
    vkCmdWriteTimestamp(m.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, m.queries, 0);
  }
  vkCmdBindPipeline(m.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m.pipeline);
  vkCmdBindDescriptorSets(m.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m.pipeline_layout, 0, 1, &m.set, 0,
                          nullptr);
  const PushConstants pc{
      m.brick_capacity, log2_pow2(m.brick_capacity), std::min(kMaxProbes, m.brick_capacity),
      m.node_capacity,  log2_pow2(m.node_capacity),  std::min(kMaxProbes, m.node_capacity),
      m.slots_per_chunk};
  vkCmdPushConstants(m.cmd, m.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
  vkCmdDispatch(m.cmd, (frame.width + kWorkgroup - 1) / kWorkgroup,
                (frame.height + kWorkgroup - 1) / kWorkgroup, 1);
  if (m.queries) vkCmdWriteTimestamp(m.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m.queries, 1);
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(m.cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0,
                       1, &to_host, 0, nullptr, 0, nullptr);
  check(vkEndCommandBuffer(m.cmd), "vkEndCommandBuffer");
  m.submit_and_wait();

  if (result.image.width() != frame.width || result.image.height() != frame.height) {
    result.image = Image(frame.width, frame.height);
  }
  std::memcpy(result.image.pixels().data(), m.buf[b_out].mapped, pixels * sizeof(glm::vec4));

  const auto* st = static_cast<const std::uint32_t*>(m.buf[b_stats].mapped);
  auto stat = [st](std::uint32_t i) {
    return std::uint64_t(st[i]) | (std::uint64_t(st[i + 1]) << 32);
  };
  BackendStats& s = result.stats;
  s = BackendStats{};
  s.rays = pixels;
  s.samples = stat(0);
  s.nodes_visited = stat(2);
  s.brick_accesses = stat(4);
  s.iterations = stat(6);
  s.cap_hits = stat(8);
  s.request_inserts = stat(10);
  s.requests_dropped = stat(12) + stat(14);
  s.distance_skipped = double(stat(16)) / kDistanceScale;
  s.distance_marched = double(stat(18)) / kDistanceScale;
  if (m.queries) {
    std::array<std::uint64_t, 2> ts{};
    check(vkGetQueryPoolResults(m.ctx->device, m.queries, 0, 2, sizeof(ts), ts.data(),
                                sizeof(std::uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    const std::uint64_t mask =
        m.ctx->timestamp_bits >= 64 ? ~0ull : (std::uint64_t(1) << m.ctx->timestamp_bits) - 1u;
    const std::uint64_t ticks = ((ts[1] & mask) - (ts[0] & mask)) & mask;
    s.ms_device = double(ticks) * double(m.ctx->props.limits.timestampPeriod) * 1e-6;
  }

  // Compact the occupied request entries, ordered like RequestSet::drain.
  auto drain = [](const std::uint32_t* set, std::uint32_t cap, std::uint32_t level_count,
                  std::vector<Request>& out) {
    out.clear();
    for (std::uint32_t i = 0; i < cap; ++i) {
      if (set[i] == kernel::RESOCT_REQUEST_KEY_NONE) continue;
      const std::uint32_t level =
          level_count ? kernel::resoct_request_key_table(set[i]) % level_count : 0u;
      out.push_back(Request{set[i], set[cap + i], level});
    }
    std::sort(out.begin(), out.end(), [](const Request& a, const Request& b) {
      if (a.level != b.level) return a.level > b.level;
      if (a.hits != b.hits) return a.hits > b.hits;
      return a.key < b.key;
    });
  };
  drain(static_cast<const std::uint32_t*>(m.buf[b_brick_requests].mapped), m.brick_capacity,
        frame.level_count, result.brick_requests);
  drain(static_cast<const std::uint32_t*>(m.buf[b_node_requests].mapped), m.node_capacity, 0,
        result.node_requests);

  result.used_cache_slots.clear();
  const auto* used = static_cast<const std::uint32_t*>(m.buf[b_used].mapped);
  for (std::size_t w = 0; w < (std::size_t(m.config.cache_slots) + 31) / 32; ++w) {
    std::uint32_t bits = used[w];
    while (bits != 0) {
      result.used_cache_slots.push_back(
          std::uint32_t(w * 32 + std::size_t(std::countr_zero(bits))));
      bits &= bits - 1u;
    }
  }
  s.ms_render =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void VulkanBackend::debug_limit_cache_buffer(std::uint64_t bytes) noexcept {
  impl_->cache_buffer_limit = bytes;
}

std::vector<std::byte> VulkanBackend::debug_read(DeviceArray array) const {
  const Impl& m = *impl_;
  if (!m.configured) throw invalid_parameter("array", "backend is not configured");
  check(vkDeviceWaitIdle(m.ctx->device), "vkDeviceWaitIdle");
  std::size_t bytes = 0;
  Binding b = b_cache;
  switch (array) {
    case DeviceArray::cache:
      bytes = std::size_t(m.config.cache_slots) * m.slot_voxels * m.voxel_bytes;
      break;
    case DeviceArray::pages:
      bytes = std::size_t(m.config.page_entries) * 4;
      b = b_pages;
      break;
    case DeviceArray::page_offsets:
      bytes = (std::size_t(m.config.page_tables) + 1) * 4;
      b = b_page_offsets;
      break;
    case DeviceArray::nodes:
      bytes = std::size_t(m.config.node_words) * 4;
      b = b_nodes;
      break;
  }
  std::vector<std::byte> out(bytes);
  if (array == DeviceArray::cache) {
    const std::size_t brick_bytes = m.slot_voxels * m.voxel_bytes;
    for (std::uint32_t s = 0; s < m.config.cache_slots; ++s) {
      std::memcpy(out.data() + std::size_t(s) * brick_bytes, m.slot_address(s), brick_bytes);
    }
  } else if (bytes) {
    std::memcpy(out.data(), m.buf[b].mapped, bytes);
  }
  return out;
}

}  // namespace resoct::vk
