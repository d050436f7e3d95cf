#pragma once
// Internal: the scatter compute pass (shaders/scatter.comp) that applies page-table and octree
// word deltas, read as (index, value) pairs from the staging ring, to device-local arrays.
#include <cstdint>
#include <memory>

#include <vulkan/vulkan.h>

#include "pipelines.hpp"
#include "vk_context.hpp"

namespace resoct::vk::detail {

/// Arrays the scatter pass writes; one descriptor set each.
enum class ScatterTarget : std::uint32_t { pages, directory, nodes, count };

class ScatterPass {
 public:
  static constexpr std::uint32_t kWorkgroup = 64;

  explicit ScatterPass(const Context& c);
  ~ScatterPass();
  ScatterPass(const ScatterPass&) = delete;
  ScatterPass& operator=(const ScatterPass&) = delete;

  /// Points the descriptor set of `t` at the ring and the target buffer. Only while no recorded,
  /// unsubmitted command uses it (the backend calls it in configure()).
  void bind(ScatterTarget t, VkBuffer ring, VkDeviceSize ring_bytes, VkBuffer target,
            VkDeviceSize target_bytes);
  /// Most pairs one record() may apply (the workgroup-count limit of one dispatch).
  std::uint32_t max_pairs() const noexcept { return max_pairs_; }
  /// Records one dispatch applying `count` pairs starting at ring word `first_word` to a target
  /// of `target_words` words. The caller orders it against other writes with barriers.
  void record(VkCommandBuffer cmd, ScatterTarget t, std::uint32_t first_word, std::uint32_t count,
              std::uint32_t target_words);

 private:
  const Context& c_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet sets_[std::uint32_t(ScatterTarget::count)] = {};
  std::unique_ptr<ComputePipelines> pipelines_;
  std::uint32_t max_pairs_ = 0;
};

}  // namespace resoct::vk::detail
