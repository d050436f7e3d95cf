// VulkanBackend::Impl lifetime: descriptor layout and set, command buffer and fence, storage
// buffers, and one-shot submission.
#include <algorithm>
#include <string>

#include "backend_impl.hpp"
#include "resoct/error.hpp"
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
}

VulkanBackend::Impl::~Impl() {
  VkDevice dev = ctx->device;
  vkDeviceWaitIdle(dev);
  release_buffers();
  timer.reset();
  render_pipelines.reset();
  if (fence) vkDestroyFence(dev, fence, nullptr);
  if (command_pool) vkDestroyCommandPool(dev, command_pool, nullptr);
  if (pool) vkDestroyDescriptorPool(dev, pool, nullptr);
  if (pipeline_layout) vkDestroyPipelineLayout(dev, pipeline_layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(dev, set_layout, nullptr);
}

std::byte* VulkanBackend::Impl::slot_address(std::uint32_t slot) const {
  const std::uint32_t c = slot / slots_per_chunk;
  return static_cast<std::byte*>(buf[detail::cache_binding(c)].mapped) +
         std::size_t(slot - c * slots_per_chunk) * slot_voxels * voxel_bytes;
}

void VulkanBackend::Impl::release_buffers() noexcept {
  for (detail::Buffer& b : buf) detail::destroy_buffer(*ctx, b);
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

void VulkanBackend::Impl::submit_and_wait() {
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  check(vkResetFences(ctx->device, 1, &fence), "vkResetFences");
  check(vkQueueSubmit(ctx->queue, 1, &si, fence), "vkQueueSubmit");
  const VkResult r = vkWaitForFences(ctx->device, 1, &fence, VK_TRUE, detail::kFenceTimeoutNs);
  if (r == VK_TIMEOUT)
    throw Error(ErrorCode::device, "vulkan: device: frame did not finish in 120 s");
  check(r, "vkWaitForFences");
}

}  // namespace resoct::vk
