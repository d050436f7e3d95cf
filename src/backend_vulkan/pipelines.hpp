#pragma once
// Internal: compute pipelines keyed by their specialization constants ("variants"), created on
// first use and cached for the backend's lifetime.
//
// A variant is a plain struct of std::uint32_t members, one per specialization constant, plus a
// static `constant_ids` array giving each member's `layout(constant_id = N)` in declaration
// order. The struct's bytes are the VkSpecializationInfo data, so the two cannot drift apart
// (static_assert below). Booleans are 0/1 members (a GLSL `const bool` constant is 32 bits).
//
// Adding a render constant (shading, iso-surface, shadows, MIP, ...):
//   1. render.comp: `layout(constant_id = N) const uint MY_SWITCH = 0u;` with an unused N
//      (ids in use: see RenderVariant::constant_ids);
//   2. append `std::uint32_t my_switch = 0;` to RenderVariant and N to constant_ids;
//   3. set it in VulkanBackend::Impl::render_variant() (vulkan_backend.cpp), the one place
//      that derives a frame's variant from its tables and the configuration.
// Each distinct variant compiles once (seconds on lavapipe), so derive constants only from
// values that change rarely.
#include <array>
#include <compare>
#include <cstring>
#include <cstdint>
#include <map>
#include <span>
#include <type_traits>
#include <vector>

#include <vulkan/vulkan.h>

namespace resoct::vk::detail {

/// Specialization constants of shaders/render.comp.
struct RenderVariant {
  std::uint32_t voxel_type = 0;  ///< resoct::VoxelType: 0 = u8, 1 = u16, 2 = f32
  std::uint32_t padded_x = 34;   ///< padded brick voxels per axis (cache addressing)
  std::uint32_t padded_y = 34;
  std::uint32_t padded_z = 34;
  std::uint32_t cache_chunks = 1;  ///< cache buffers in use (1..8)
  std::uint32_t workgroup_x = 8;   ///< local_size_x_id / local_size_y_id
  std::uint32_t workgroup_y = 8;
  /// Effect mask RESOCT_EFFECTS (kernel/effects.glsl.h): one pipeline per effect set in use.
  std::uint32_t effects = 0;

  static constexpr std::array<std::uint32_t, 8> constant_ids = {0, 1, 2, 3, 4, 10, 11, 30};
  friend auto operator<=>(const RenderVariant&, const RenderVariant&) = default;
};

/// Specialization constants of shaders/scatter.comp.
struct ScatterVariant {
  std::uint32_t workgroup_x = 64;  ///< local_size_x_id

  static constexpr std::array<std::uint32_t, 1> constant_ids = {0};
  friend auto operator<=>(const ScatterVariant&, const ScatterVariant&) = default;
};

/// One shader module and its pipelines; not thread-safe (the backend is single-threaded).
class ComputePipelines {
 public:
  /// Takes SPIR-V words (copied into a module) and a layout that must outlive this object.
  ComputePipelines(VkDevice device, std::span<const std::uint32_t> spirv, VkPipelineLayout layout);
  ~ComputePipelines();
  ComputePipelines(const ComputePipelines&) = delete;
  ComputePipelines& operator=(const ComputePipelines&) = delete;

  /// The pipeline for these constants, compiled on first use. Throws Error(device /
  /// out_of_memory) when the driver cannot compile it.
  template <class Variant>
  VkPipeline get(const Variant& v) {
    static_assert(std::is_trivially_copyable_v<Variant> &&
                      sizeof(Variant) == sizeof(std::uint32_t) * Variant::constant_ids.size(),
                  "a variant holds exactly one std::uint32_t per specialization constant");
    std::array<std::uint32_t, Variant::constant_ids.size()> words{};
    static_assert(sizeof(words) == sizeof(Variant));
    std::memcpy(words.data(), &v, sizeof(v));
    Key key(words.begin(), words.end());
    auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    VkPipeline p = create(Variant::constant_ids, words);
    cache_.emplace(std::move(key), p);
    return p;
  }
  /// Pipelines compiled so far (tests check that variants are reused).
  std::size_t size() const noexcept { return cache_.size(); }

 private:
  using Key = std::vector<std::uint32_t>;
  VkPipeline create(std::span<const std::uint32_t> ids, std::span<const std::uint32_t> values);

  VkDevice device_;
  VkPipelineLayout layout_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  std::map<Key, VkPipeline> cache_;
};

}  // namespace resoct::vk::detail
