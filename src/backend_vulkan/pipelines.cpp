#include "pipelines.hpp"

#include <vector>

#include "vk_context.hpp"

namespace resoct::vk::detail {

ComputePipelines::ComputePipelines(VkDevice device, std::span<const std::uint32_t> spirv,
                                   VkPipelineLayout layout)
    : device_(device), layout_(layout) {
  VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smci.codeSize = spirv.size_bytes();
  smci.pCode = spirv.data();
  check(vkCreateShaderModule(device_, &smci, nullptr, &module_), "vkCreateShaderModule");
}

ComputePipelines::~ComputePipelines() {
  for (auto& [key, p] : cache_) vkDestroyPipeline(device_, p, nullptr);
  if (module_) vkDestroyShaderModule(device_, module_, nullptr);
}

VkPipeline ComputePipelines::create(std::span<const std::uint32_t> ids,
                                    std::span<const std::uint32_t> values) {
  std::vector<VkSpecializationMapEntry> entries(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    entries[i] = {ids[i], std::uint32_t(i * sizeof(std::uint32_t)), sizeof(std::uint32_t)};
  }
  VkSpecializationInfo si{};
  si.mapEntryCount = std::uint32_t(entries.size());
  si.pMapEntries = entries.data();
  si.dataSize = values.size_bytes();
  si.pData = values.data();
  VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cpci.stage.module = module_;
  cpci.stage.pName = "main";
  cpci.stage.pSpecializationInfo = &si;
  cpci.layout = layout_;
  VkPipeline p = VK_NULL_HANDLE;
  check(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &cpci, nullptr, &p),
        "vkCreateComputePipelines");
  return p;
}

}  // namespace resoct::vk::detail
