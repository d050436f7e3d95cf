// Host → device: VulkanBackend::update() (bricks, page table, octree words) and the per-frame
// tables of render(), all through the staging ring (see backend_impl.hpp).
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "backend_impl.hpp"
#include "resoct/base/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"

namespace resoct::vk {

using namespace detail;

namespace {

// Flattens word deltas into (index, value) pairs with one pair per index, the last delta of an
// index winning (the order in which FrameUpdate lists them), so that scatter invocations never
// race on a word.
template <class Delta>
std::vector<std::uint32_t> unique_pairs(std::span<const Delta> deltas) {
  std::vector<std::uint32_t> order(deltas.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return deltas[a].index < deltas[b].index;
  });
  std::vector<std::uint32_t> pairs;
  pairs.reserve(2 * deltas.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Delta& d = deltas[order[k]];
    if (k + 1 < order.size() && deltas[order[k + 1]].index == d.index) continue;
    pairs.push_back(std::uint32_t(d.index));
    pairs.push_back(d.value);
  }
  return pairs;
}

std::span<const std::byte> bytes_of(std::span<const std::uint32_t> words) {
  return std::as_bytes(words);
}

}  // namespace

void VulkanBackend::update(const FrameUpdate& u) {
  Impl& m = *impl_;
  if (!m.configured) throw invalid_parameter("update", "backend is not configured");
  const std::size_t brick_bytes = m.slot_voxels * m.voxel_bytes;
  const std::size_t page_count =
      std::size_t(m.config.page_pool_blocks) * kernel::RESOCT_PAGE_BLOCK_ENTRIES;
  const std::size_t dir_count = m.config.directory_entries;
  const std::size_t node_count = std::size_t(m.config.node_words);
  // Validate everything before recording anything, so that a rejected update changes nothing.
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
  }
  if (u.pages_full) {
    if (u.all_pages.size() > page_count) {
      throw invalid_parameter("update", "full page pool of " + std::to_string(u.all_pages.size()) +
                                            " words, at most " + std::to_string(page_count));
    }
    if (u.all_directory.size() != dir_count) {
      throw invalid_parameter("update", "full page directory of " +
                                            std::to_string(u.all_directory.size()) +
                                            " entries, expected " + std::to_string(dir_count));
    }
    if (u.directory_offsets.size() != std::size_t(m.config.page_tables) + 1u) {
      throw invalid_parameter("update", "directory_offsets has the wrong size");
    }
    for (std::uint32_t o : u.directory_offsets) {
      if (o > dir_count) throw invalid_parameter("update", "directory offset out of range");
    }
    for (std::uint32_t b : u.all_directory) {
      if (b >= m.config.page_pool_blocks)
        throw invalid_parameter("update", "directory names no pool block");
    }
  }
  for (const PageDelta& d : u.page_deltas) {
    if (d.index >= page_count) throw invalid_parameter("update", "page delta out of range");
  }
  for (const PageDelta& d : u.directory_deltas) {
    if (d.index >= dir_count || d.value >= m.config.page_pool_blocks)
      throw invalid_parameter("update", "directory delta out of range");
  }
  if (u.nodes_full && u.all_nodes.size() != node_count) {
    throw invalid_parameter("update", "full octree of " + std::to_string(u.all_nodes.size()) +
                                          " words, expected " + std::to_string(node_count));
  }
  for (const OctreeWordDelta& d : u.node_deltas) {
    if (d.index >= node_count) throw invalid_parameter("update", "octree delta out of range");
  }

  // Bricks: the last upload of a slot wins; distinct slots are disjoint copy regions.
  std::vector<std::uint32_t> last(u.bricks.size());
  {
    std::vector<std::uint32_t> order(u.bricks.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return u.bricks[a].cache_slot < u.bricks[b].cache_slot;
    });
    last.clear();
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (k + 1 < order.size() &&
          u.bricks[order[k + 1]].cache_slot == u.bricks[order[k]].cache_slot) {
        continue;
      }
      last.push_back(order[k]);
    }
  }
  const auto page_pairs = unique_pairs(u.page_deltas);
  const auto dir_pairs = unique_pairs(u.directory_deltas);
  const auto node_pairs = unique_pairs(u.node_deltas);
  if (last.empty() && !u.pages_full && page_pairs.empty() && dir_pairs.empty() && !u.nodes_full &&
      node_pairs.empty()) {
    return;
  }
  m.begin_batch();
  // Earlier updates in this batch may have written the same words: order against them.
  m.barrier();
  for (std::uint32_t i : last) {
    const auto [buffer, offset] = m.slot_location(u.bricks[i].cache_slot);
    m.stage_copy(buffer, offset, u.bricks[i].voxels);
  }
  // The CPU backend applies a full array before the deltas of the same update; so does this.
  if (u.pages_full) {
    // The pool beyond the host's prefix reads UNMAPPED (disjoint from the copy: no barrier).
    const VkDeviceSize prefix = VkDeviceSize(u.all_pages.size()) * 4;
    if (prefix < VkDeviceSize(page_count) * 4) {
      vkCmdFillBuffer(m.cmd, m.buf[b_pages].buffer, prefix, VkDeviceSize(page_count) * 4 - prefix,
                      0);
    }
    m.stage_copy(m.buf[b_pages].buffer, 0, bytes_of(u.all_pages));
    m.stage_copy(m.buf[b_directory].buffer, 0, bytes_of(u.all_directory));
    m.stage_copy(m.buf[b_directory_offsets].buffer, 0, bytes_of(u.directory_offsets));
  }
  if (u.nodes_full) m.stage_copy(m.buf[b_nodes].buffer, 0, bytes_of(u.all_nodes));
  if (!page_pairs.empty() || !dir_pairs.empty() || !node_pairs.empty()) {
    m.begin_batch();
    if (u.pages_full || u.nodes_full) m.barrier();
    m.stage_scatter(ScatterTarget::pages, page_pairs, std::uint32_t(page_count));
    m.stage_scatter(ScatterTarget::directory, dir_pairs, std::uint32_t(dir_count));
    m.stage_scatter(ScatterTarget::nodes, node_pairs, std::uint32_t(node_count));
  }
}

void VulkanBackend::Impl::upload_tables(const FrameTables& tables) {
  const kernel::ResoctFrame& frame = tables.frame;
  const std::size_t pixels = std::size_t(frame.width) * frame.height;
  // Buffers may be recreated here, so nothing recorded may refer to them yet.
  ensure(b_slots, std::max<std::size_t>(tables.slots.size(), 1) * sizeof(kernel::ResoctSlotInfo),
         "slot table");
  ensure(b_levels, tables.levels.size() * sizeof(kernel::ResoctLevelInfo), "level table");
  ensure(b_depths, tables.depths.size() * sizeof(kernel::ResoctDepthInfo), "depth table");
  ensure(b_tf, std::max<std::size_t>(tables.tf_luts.size(), 1) * sizeof(glm::vec4),
         "transfer functions");
  ensure(b_preint, std::max<std::size_t>(tables.preint_tables.size(), 1) * sizeof(glm::vec4),
         "pre-integration tables");
  const VkBuffer step_luts_before = buf[b_step_luts].buffer;
  ensure(b_step_luts, std::max<std::size_t>(tables.step_luts.size(), 1) * sizeof(glm::vec4),
         "step-level LUTs");
  if (buf[b_step_luts].buffer != step_luts_before) step_luts_on_device = 0;
  // One word per node whether or not the tables have bits: the kernel reads any node's word.
  const auto node_count = std::size_t(octree_node_count(tables.depths));
  const VkBuffer visible_before = buf[b_visible_subtrees].buffer;
  ensure(b_visible_subtrees, std::max<std::size_t>(node_count, 1) * sizeof(std::uint32_t),
         "visible subtrees");
  if (buf[b_visible_subtrees].buffer != visible_before) visible_subtrees_on_device = 0;
  ensure(b_out, pixels * sizeof(glm::vec4), "output image");
  begin_batch();
  // ResoctFrame followed by ResoctFxFrame (render.comp's FrameBuf).
  stage_copy(buf[b_frame].buffer, 0, std::as_bytes(std::span(&frame, 1)));
  stage_copy(buf[b_frame].buffer, sizeof(frame), std::as_bytes(std::span(&tables.fx, 1)));
  stage_copy(buf[b_slots].buffer, 0, std::as_bytes(std::span(tables.slots)));
  stage_copy(buf[b_levels].buffer, 0, std::as_bytes(std::span(tables.levels)));
  stage_copy(buf[b_depths].buffer, 0, std::as_bytes(std::span(tables.depths)));
  stage_copy(buf[b_tf].buffer, 0, std::as_bytes(std::span(tables.tf_luts)));
  if (!tables.preint_tables.empty()) {
    stage_copy(buf[b_preint].buffer, 0, std::as_bytes(std::span(tables.preint_tables)));
  }
  // Version 0 (tables not from build_frame_tables) is always sent. render() records the version
  // only once the frame ran, so a failed submission sends them again.
  if (!tables.step_luts.empty() &&
      (tables.step_luts_version == 0 || tables.step_luts_version != step_luts_on_device)) {
    stage_copy(buf[b_step_luts].buffer, 0, std::as_bytes(std::span(tables.step_luts)));
  }
  if (tables.visible_subtrees.empty()) {
    if (visible_subtrees_on_device != kZeroVisibleSubtrees) {
      vkCmdFillBuffer(cmd, buf[b_visible_subtrees].buffer, 0, VK_WHOLE_SIZE, 0);
    }
  } else if (tables.visible_subtrees_version == 0 ||
             tables.visible_subtrees_version != visible_subtrees_on_device) {
    stage_copy(buf[b_visible_subtrees].buffer, 0,
               std::as_bytes(std::span(tables.visible_subtrees)));
  }
}

}  // namespace resoct::vk
