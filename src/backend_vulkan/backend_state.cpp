// VulkanBackend::Impl lifetime: descriptor layout and set, command buffer and fence, device
// buffers, and the command batch (begin, barriers, staged copies and scatters, flush).
#include <algorithm>
#include <cstring>
#include <string>

#include "backend_impl.hpp"
#include "resoct/base/error.hpp"
#include "resoct_render_spv.h"

namespace resoct::vk {

using detail::Binding;
using detail::binding_count;
using detail::check;

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
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(detail::PushConstants)};
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
  render_pipelines = std::make_unique<detail::ComputePipelines>(
      dev, std::span<const std::uint32_t>(resoct_render_spv), pipeline_layout);
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
  timer = std::make_unique<detail::GpuTimer>(*ctx);
  scatter = std::make_unique<detail::ScatterPass>(*ctx);
}

VulkanBackend::Impl::~Impl() {
  VkDevice dev = ctx->device;
  vkDeviceWaitIdle(dev);
  release_buffers();
  scatter.reset();
  timer.reset();
  render_pipelines.reset();
  if (fence) vkDestroyFence(dev, fence, nullptr);
  if (command_pool) vkDestroyCommandPool(dev, command_pool, nullptr);
  if (pool) vkDestroyDescriptorPool(dev, pool, nullptr);
  if (pipeline_layout) vkDestroyPipelineLayout(dev, pipeline_layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(dev, set_layout, nullptr);
}

std::pair<VkBuffer, VkDeviceSize> VulkanBackend::Impl::slot_location(std::uint32_t slot) const {
  const std::uint32_t c = slot / slots_per_chunk;
  return {buf[detail::cache_binding(c)].buffer,
          VkDeviceSize(slot - c * slots_per_chunk) * slot_voxels * voxel_bytes};
}

void VulkanBackend::Impl::release_buffers() noexcept {
  for (detail::Buffer& b : buf) detail::destroy_buffer(*ctx, b);
  ring.destroy(*ctx);
  detail::destroy_buffer(*ctx, readback);
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
  descriptors_dirty = true;
  buf[b] = detail::create_buffer(
      *ctx, std::min<VkDeviceSize>(size, ctx->props.limits.maxStorageBufferRange),
      detail::kDeviceUsage, detail::MemoryUse::device, what);
}

void VulkanBackend::Impl::ensure_readback(VkDeviceSize bytes) {
  if (readback.buffer != VK_NULL_HANDLE && readback.size >= bytes) return;
  const VkDeviceSize size = std::max<VkDeviceSize>(bytes, readback.size * 2);
  detail::destroy_buffer(*ctx, readback);
  readback = detail::create_buffer(*ctx, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                   detail::MemoryUse::readback, "readback buffer");
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

void VulkanBackend::Impl::begin_batch() {
  if (recording) return;
  check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  recording = true;
  // The previous batch finished (its fence was waited for), but its writes still need a memory
  // dependency to be visible to this one.
  barrier();
}

void VulkanBackend::Impl::barrier() {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  const VkPipelineStageFlags stages =
      VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  vkCmdPipelineBarrier(cmd, stages, stages, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

void VulkanBackend::Impl::flush() {
  if (!recording) return;
  recording = false;
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  check(vkResetFences(ctx->device, 1, &fence), "vkResetFences");
  // Host writes to the ring before vkQueueSubmit are visible to the batch (submission order).
  check(vkQueueSubmit(ctx->queue, 1, &si, fence), "vkQueueSubmit");
  const VkResult r = vkWaitForFences(ctx->device, 1, &fence, VK_TRUE, detail::kFenceTimeoutNs);
  if (r == VK_TIMEOUT)
    throw Error(ErrorCode::device, "vulkan: device: frame did not finish in 120 s");
  check(r, "vkWaitForFences");
  ring.reset();
}

void VulkanBackend::Impl::discard_batch() noexcept {
  if (!recording) return;
  recording = false;
  vkEndCommandBuffer(cmd);  // reset by the next begin_batch()
  ring.reset();
}

void VulkanBackend::Impl::stage_copy(VkBuffer dst, VkDeviceSize offset,
                                     std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    begin_batch();
    if (ring.free_bytes() == 0) {
      flush();
      begin_batch();
    }
    VkDeviceSize n = 0;
    const VkDeviceSize at = ring.take(bytes.size(), n);
    std::memcpy(ring.at(at), bytes.data(), std::size_t(n));
    const VkBufferCopy region{at, offset, n};
    vkCmdCopyBuffer(cmd, ring.buffer(), dst, 1, &region);
    bytes = bytes.subspan(std::size_t(n));
    offset += n;
  }
}

void VulkanBackend::Impl::stage_scatter(detail::ScatterTarget target,
                                        std::span<const std::uint32_t> pairs,
                                        std::uint32_t target_words) {
  constexpr VkDeviceSize kPair = 2 * sizeof(std::uint32_t);
  while (!pairs.empty()) {
    begin_batch();
    if (ring.free_bytes() < kPair) {
      flush();
      begin_batch();
    }
    const VkDeviceSize want =
        std::min<VkDeviceSize>(pairs.size() / 2, scatter->max_pairs()) * kPair;
    VkDeviceSize n = 0;
    const VkDeviceSize at = ring.take(want - want % kPair, n);
    n -= n % kPair;
    std::memcpy(ring.at(at), pairs.data(), std::size_t(n));
    scatter->record(cmd, target, std::uint32_t(at / sizeof(std::uint32_t)),
                    std::uint32_t(n / kPair), target_words);
    pairs = pairs.subspan(std::size_t(n / sizeof(std::uint32_t)));
  }
}

}  // namespace resoct::vk
