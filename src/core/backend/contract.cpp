#include <string>

#include "resoct/backend/backend.hpp"
#include "resoct/base/error.hpp"
#include "resoct/scene/step_lut.hpp"
#include "resoct/scene/transfer_function.hpp"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct {

std::uint64_t octree_node_count(std::span<const kernel::ResoctDepthInfo> depths) noexcept {
  if (depths.empty()) return 0;
  const kernel::ResoctDepthInfo& last = depths.back();
  return std::uint64_t(last.first_node) + std::uint64_t(last.count_x) * last.count_y * last.count_z;
}

void check_page_table_config(const BackendConfig& config) {
  if (config.page_pool_blocks == 0 ||
      config.page_pool_blocks > kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS) {
    throw invalid_parameter("config", "page_pool_blocks must be 1.." +
                                          std::to_string(kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS));
  }
  if (config.directory_entries >= kernel::RESOCT_REQUEST_MAX_DIRECTORY) {
    throw invalid_parameter("config", "directory_entries must be below 2^31 - 1");
  }
}

void check_frame_tables(const FrameTables& t, const BackendConfig& config) {
  const kernel::ResoctFrame& f = t.frame;
  auto fail = [](const std::string& why) { throw invalid_parameter("tables", why); };
  if (f.width == 0 || f.height == 0) fail("empty image");
  // A lens adds a second bank of slot entries (outside the lens) after the first.
  if (f.lens_enabled > 1u || t.slots.size() != std::size_t(f.slot_count) * (1u + f.lens_enabled) ||
      f.slot_count > kernel::RESOCT_MAX_SLOTS) {
    fail("slot table size differs from slot_count");
  }
  if (f.slice_count > kernel::RESOCT_MAX_SLICES) fail("slice_count above RESOCT_MAX_SLICES");
  // A sample shift below -1/2 step would put the first sample before the volume's entry.
  for (float j : {f.jitter_x, f.jitter_y, f.jitter_sample}) {
    if (!(j >= -0.5f && j < 0.5f)) fail("jitter outside [-0.5, 0.5)");
  }
  if (t.levels.size() != f.level_count || f.level_count == 0 || f.level_count > 32) {
    fail("level table size differs from level_count");
  }
  if (t.depths.size() != f.depth_count || f.depth_count == 0) {
    fail("depth table size differs from depth_count");
  }
  if (std::size_t(f.page_slot_count) * f.level_count != config.page_tables) {
    fail("page_slot_count * level_count differs from the configured page tables");
  }
  if (t.tf_luts.size() != std::size_t(f.page_slot_count) * kTfLutSize) {
    fail("tf_luts size differs from page_slot_count * RESOCT_TF_LUT_SIZE");
  }
  if ((t.fx.effects & kernel::RESOCT_EFFECT_PREINT) != 0u &&
      t.preint_tables.size() != std::size_t(f.page_slot_count) * 2u * kTfLutSize) {
    fail("preint_tables size differs from page_slot_count * 2 * RESOCT_TF_LUT_SIZE");
  }
  // Step levels (kernel/step_lut.glsl.h): a shift that keeps the ratio's exponent, and one LUT
  // per shown-or-not page slot and level.
  if (f.step_level_count > kMaxStepLevels || f.step_level_shift > 23u ||
      (f.step_level_count != 0u && (std::uint64_t(f.step_level_first) + f.step_level_count)
                                           << f.step_level_shift >
                                       0xFFFFFFFFull)) {
    fail("step levels out of range");
  }
  if (t.step_luts.size() !=
      std::size_t(f.page_slot_count) * f.step_level_count * std::size_t(kTfLutSize)) {
    fail("step_luts size differs from page_slot_count * step_level_count * RESOCT_TF_LUT_SIZE");
  }
  if (std::size_t(t.depths.back().first_node) * f.node_slot_count * 4u >= config.node_words + 1u &&
      config.node_words != 0) {
    fail("octree is smaller than the depth table");
  }
  // One word per node of the depth table, or none.
  if (!t.visible_subtrees.empty() && t.visible_subtrees.size() != octree_node_count(t.depths)) {
    fail("visible_subtrees size differs from the depth table's node count");
  }
  if (glm::uvec3(f.padded_x, f.padded_y, f.padded_z) != config.padded_brick) {
    fail("padded brick size differs from the configuration");
  }
  for (const auto& s : t.slots) {
    if (s.slot >= f.page_slot_count || s.finest_level > s.coarsest_level ||
        s.coarsest_level >= f.level_count) {
      fail("slot entry out of range");
    }
  }
}

}  // namespace resoct
