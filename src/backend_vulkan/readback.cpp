// Device → host: the frame's image, statistics, request sets and used cache slots, and the
// test-support array reads.
#include <algorithm>
#include <bit>
#include <cstring>

#include "backend_impl.hpp"
#include "resoct/base/error.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct::vk {

using namespace detail;

namespace {

// Compacts the occupied entries of a device request set (keys in [0, cap), hits in
// [cap, 2 cap)), ordered like RequestSet::drain.
// Brick keys name pool blocks, not levels, so every request has level 0 (as on the CPU).
void drain(const std::uint32_t* set, std::uint32_t cap, std::vector<Request>& out) {
  out.clear();
  for (std::uint32_t i = 0; i < cap; ++i) {
    if (set[i] == kernel::RESOCT_REQUEST_KEY_NONE) continue;
    out.push_back(Request{set[i], set[cap + i], 0u});
  }
  std::sort(out.begin(), out.end(), [](const Request& a, const Request& b) {
    if (a.level != b.level) return a.level > b.level;
    if (a.hits != b.hits) return a.hits > b.hits;
    return a.key < b.key;
  });
}

}  // namespace

std::uint64_t handle_of(VkBuffer buffer) noexcept {
  // A pointer on 64-bit platforms, a uint64_t on 32-bit ones: copied bit for bit either way.
  static_assert(sizeof(VkBuffer) <= sizeof(std::uint64_t));
  std::uint64_t h = 0;
  std::memcpy(&h, &buffer, sizeof(buffer));
  return h;
}

VkBuffer buffer_of(const DeviceImage& image) noexcept {
  VkBuffer b = VK_NULL_HANDLE;
  std::memcpy(&b, &image.handle, sizeof(b));
  return b;
}

ReadbackLayout detail::readback_layout(std::size_t pixels, std::uint32_t brick_capacity,
                                       std::uint32_t node_capacity, std::uint32_t cache_slots) {
  ReadbackLayout l;
  l.image = 0;
  l.brick_requests = VkDeviceSize(pixels) * sizeof(glm::vec4);
  l.node_requests = l.brick_requests + VkDeviceSize(brick_capacity) * 8;
  l.used = l.node_requests + VkDeviceSize(node_capacity) * 8;
  l.stats = l.used + (VkDeviceSize(cache_slots) + 31) / 32 * 4;
  l.total = l.stats + kStatWords * 4;
  return l;
}

ReadbackLayout VulkanBackend::Impl::readback_layout(const kernel::ResoctFrame& frame,
                                                    bool image_to_host) const {
  const std::size_t pixels = image_to_host ? std::size_t(frame.width) * frame.height : 0;
  return detail::readback_layout(pixels, brick_capacity, node_capacity, config.cache_slots);
}

void VulkanBackend::Impl::record_readback(const kernel::ResoctFrame& frame, bool image_to_host) {
  const ReadbackLayout l = readback_layout(frame, image_to_host);
  barrier();
  auto copy = [&](Binding b, VkDeviceSize to, VkDeviceSize bytes) {
    if (bytes == 0) return;
    const VkBufferCopy region{0, to, bytes};
    vkCmdCopyBuffer(cmd, buf[b].buffer, readback.buffer, 1, &region);
  };
  copy(b_out, l.image, l.brick_requests - l.image);  // 0 bytes when the image stays on the device
  copy(b_brick_requests, l.brick_requests, l.node_requests - l.brick_requests);
  copy(b_node_requests, l.node_requests, l.used - l.node_requests);
  copy(b_used, l.used, l.stats - l.used);
  copy(b_stats, l.stats, l.total - l.stats);
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &to_host, 0, nullptr, 0, nullptr);
}

void VulkanBackend::Impl::read_results(const kernel::ResoctFrame& frame, bool image_to_host,
                                       FrameResult& result) const {
  const std::size_t pixels = std::size_t(frame.width) * frame.height;
  const ReadbackLayout l = readback_layout(frame, image_to_host);
  const auto* base = static_cast<const std::byte*>(readback.mapped);
  if (image_to_host) {
    if (result.image.width() != frame.width || result.image.height() != frame.height) {
      result.image = Image(frame.width, frame.height);
    }
    std::memcpy(result.image.pixels().data(), base + l.image, pixels * sizeof(glm::vec4));
    result.device_image = DeviceImage{};
  } else {
    // The kernel wrote the image to b_out from offset 0, rows top to bottom (render.comp).
    DeviceImage& d = result.device_image;
    d.handle = handle_of(buf[b_out].buffer);
    d.offset = 0;
    d.bytes = std::uint64_t(pixels) * sizeof(glm::vec4);
    d.width = frame.width;
    d.height = frame.height;
  }

  const auto* st = reinterpret_cast<const std::uint32_t*>(base + l.stats);
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
  s.gradient_evals = stat(20);
  s.shadow_rays = stat(22);
  s.ms_device = timer->ms();

  drain(reinterpret_cast<const std::uint32_t*>(base + l.brick_requests), brick_capacity,
        result.brick_requests);
  drain(reinterpret_cast<const std::uint32_t*>(base + l.node_requests), node_capacity,
        result.node_requests);

  result.used_cache_slots.clear();
  const auto* used = reinterpret_cast<const std::uint32_t*>(base + l.used);
  for (std::size_t w = 0; w < (std::size_t(config.cache_slots) + 31) / 32; ++w) {
    std::uint32_t bits = used[w];
    while (bits != 0) {
      result.used_cache_slots.push_back(
          std::uint32_t(w * 32 + std::size_t(std::countr_zero(bits))));
      bits &= bits - 1u;
    }
  }
}

std::vector<std::byte> VulkanBackend::debug_read(DeviceArray array) const {
  Impl& m = *impl_;
  if (!m.configured) throw invalid_parameter("array", "backend is not configured");
  // Apply pending updates first: the read must see them.
  m.flush();
  std::size_t bytes = 0;
  Binding b = b_cache;
  switch (array) {
    case DeviceArray::cache:
      bytes = std::size_t(m.config.cache_slots) * m.slot_voxels * m.voxel_bytes;
      break;
    case DeviceArray::pages:
      bytes = std::size_t(m.config.page_pool_blocks) * kernel::RESOCT_PAGE_BLOCK_ENTRIES * 4;
      b = b_pages;
      break;
    case DeviceArray::directory:
      bytes = std::size_t(m.config.directory_entries) * 4;
      b = b_directory;
      break;
    case DeviceArray::directory_offsets:
      bytes = (std::size_t(m.config.page_tables) + 1) * 4;
      b = b_directory_offsets;
      break;
    case DeviceArray::nodes:
      bytes = std::size_t(m.config.node_words) * 4;
      b = b_nodes;
      break;
  }
  std::vector<std::byte> out(bytes);
  if (bytes == 0) return out;
  m.ensure_readback(bytes);
  m.begin_batch();
  if (array == DeviceArray::cache) {
    // Chunk c holds slots [c * slots_per_chunk, ...) from its offset 0.
    const VkDeviceSize chunk_bytes =
        VkDeviceSize(m.slots_per_chunk) * m.slot_voxels * m.voxel_bytes;
    for (std::uint32_t c = 0; c < m.chunks; ++c) {
      const VkDeviceSize from = c * chunk_bytes;
      const VkDeviceSize n = std::min<VkDeviceSize>(chunk_bytes, bytes - from);
      const VkBufferCopy region{0, from, n};
      vkCmdCopyBuffer(m.cmd, m.buf[cache_binding(c)].buffer, m.readback.buffer, 1, &region);
    }
  } else {
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(m.cmd, m.buf[b].buffer, m.readback.buffer, 1, &region);
  }
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(m.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &to_host, 0, nullptr, 0, nullptr);
  m.flush();
  invalidate(*m.ctx, m.readback);
  std::memcpy(out.data(), m.readback.mapped, bytes);
  return out;
}

}  // namespace resoct::vk
