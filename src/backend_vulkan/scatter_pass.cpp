#include "scatter_pass.hpp"

#include <algorithm>
#include <array>
#include <span>

#include "resoct_scatter_spv.h"

namespace resoct::vk::detail {

namespace {
struct ScatterPush {
  std::uint32_t first_word, count, dst_words;
};
constexpr std::uint32_t kSets = std::uint32_t(ScatterTarget::count);
}  // namespace

ScatterPass::ScatterPass(const Context& c) : c_(c) {
  std::array<VkDescriptorSetLayoutBinding, 2> bindings{};
  for (std::uint32_t i = 0; i < 2; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = std::uint32_t(bindings.size());
  lci.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(c.device, &lci, nullptr, &set_layout_),
        "vkCreateDescriptorSetLayout (scatter)");
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(ScatterPush)};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &set_layout_;
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &range;
  check(vkCreatePipelineLayout(c.device, &plci, nullptr, &layout_),
        "vkCreatePipelineLayout (scatter)");
  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * kSets};
  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = kSets;
  dpci.poolSizeCount = 1;
  dpci.pPoolSizes = &ps;
  check(vkCreateDescriptorPool(c.device, &dpci, nullptr, &pool_),
        "vkCreateDescriptorPool (scatter)");
  std::array<VkDescriptorSetLayout, kSets> layouts;
  layouts.fill(set_layout_);
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = pool_;
  dsai.descriptorSetCount = kSets;
  dsai.pSetLayouts = layouts.data();
  check(vkAllocateDescriptorSets(c.device, &dsai, sets_), "vkAllocateDescriptorSets (scatter)");
  pipelines_ = std::make_unique<ComputePipelines>(
      c.device, std::span<const std::uint32_t>(resoct_scatter_spv), layout_);
  max_pairs_ = std::uint32_t(std::min<std::uint64_t>(
      std::uint64_t(c.props.limits.maxComputeWorkGroupCount[0]) * kWorkgroup, std::uint64_t(1)
                                                                                  << 30));
}

ScatterPass::~ScatterPass() {
  pipelines_.reset();
  if (pool_) vkDestroyDescriptorPool(c_.device, pool_, nullptr);
  if (layout_) vkDestroyPipelineLayout(c_.device, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(c_.device, set_layout_, nullptr);
}

void ScatterPass::bind(ScatterTarget t, VkBuffer ring, VkDeviceSize ring_bytes, VkBuffer target,
                       VkDeviceSize target_bytes) {
  const std::array<VkDescriptorBufferInfo, 2> info = {
      {{ring, 0, ring_bytes}, {target, 0, target_bytes}}};
  std::array<VkWriteDescriptorSet, 2> writes{};
  for (std::uint32_t i = 0; i < 2; ++i) {
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = sets_[std::uint32_t(t)];
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &info[i];
  }
  vkUpdateDescriptorSets(c_.device, 2, writes.data(), 0, nullptr);
}

void ScatterPass::record(VkCommandBuffer cmd, ScatterTarget t, std::uint32_t first_word,
                         std::uint32_t count, std::uint32_t target_words) {
  if (count == 0) return;
  ScatterVariant v;
  v.workgroup_x = kWorkgroup;
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_->get(v));
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1,
                          &sets_[std::uint32_t(t)], 0, nullptr);
  const ScatterPush push{first_word, count, target_words};
  vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
  vkCmdDispatch(cmd, (count + kWorkgroup - 1) / kWorkgroup, 1, 1);
}

}  // namespace resoct::vk::detail
