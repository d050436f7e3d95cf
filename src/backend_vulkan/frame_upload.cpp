// Host → device: VulkanBackend::update() (bricks, page table, octree words) and the per-frame
// tables of render().
#include <algorithm>
#include <cstring>
#include <string>

#include "backend_impl.hpp"
#include "resoct/error.hpp"

namespace resoct::vk {

using namespace detail;

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

void VulkanBackend::Impl::upload_tables(const FrameTables& tables) {
  const kernel::ResoctFrame& frame = tables.frame;
  const std::size_t pixels = std::size_t(frame.width) * frame.height;
  ensure(b_slots, std::max<std::size_t>(tables.slots.size(), 1) * sizeof(kernel::ResoctSlotInfo),
         "slot table");
  ensure(b_levels, tables.levels.size() * sizeof(kernel::ResoctLevelInfo), "level table");
  ensure(b_depths, tables.depths.size() * sizeof(kernel::ResoctDepthInfo), "depth table");
  ensure(b_tf, std::max<std::size_t>(tables.tf_luts.size(), 1) * sizeof(glm::vec4),
         "transfer functions");
  ensure(b_out, pixels * sizeof(glm::vec4), "output image");
  std::memcpy(buf[b_frame].mapped, &frame, sizeof(frame));
  std::memcpy(static_cast<std::byte*>(buf[b_frame].mapped) + sizeof(frame), &tables.fx,
              sizeof(tables.fx));
  std::memcpy(buf[b_slots].mapped, tables.slots.data(),
              tables.slots.size() * sizeof(tables.slots[0]));
  std::memcpy(buf[b_levels].mapped, tables.levels.data(),
              tables.levels.size() * sizeof(tables.levels[0]));
  std::memcpy(buf[b_depths].mapped, tables.depths.data(),
              tables.depths.size() * sizeof(tables.depths[0]));
  std::memcpy(buf[b_tf].mapped, tables.tf_luts.data(), tables.tf_luts.size() * sizeof(glm::vec4));
}

}  // namespace resoct::vk
