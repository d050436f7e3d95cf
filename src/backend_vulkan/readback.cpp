// Device → host: the frame's image, statistics, request sets and used cache slots, and the
// test-support array reads.
#include <algorithm>
#include <bit>
#include <cstring>

#include "backend_impl.hpp"
#include "resoct/error.hpp"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct::vk {

using namespace detail;

namespace {

// Compacts the occupied entries of a device request set (keys in [0, cap), hits in
// [cap, 2 cap)), ordered like RequestSet::drain.
void drain(const std::uint32_t* set, std::uint32_t cap, std::uint32_t level_count,
           std::vector<Request>& out) {
  out.clear();
  for (std::uint32_t i = 0; i < cap; ++i) {
    if (set[i] == kernel::RESOCT_REQUEST_KEY_NONE) continue;
    const std::uint32_t level =
        level_count ? kernel::resoct_request_key_table(set[i]) % level_count : 0u;
    out.push_back(Request{set[i], set[cap + i], level});
  }
  std::sort(out.begin(), out.end(), [](const Request& a, const Request& b) {
    if (a.level != b.level) return a.level > b.level;
    if (a.hits != b.hits) return a.hits > b.hits;
    return a.key < b.key;
  });
}

}  // namespace

void VulkanBackend::Impl::read_results(const kernel::ResoctFrame& frame,
                                       FrameResult& result) const {
  const std::size_t pixels = std::size_t(frame.width) * frame.height;
  if (result.image.width() != frame.width || result.image.height() != frame.height) {
    result.image = Image(frame.width, frame.height);
  }
  std::memcpy(result.image.pixels().data(), buf[b_out].mapped, pixels * sizeof(glm::vec4));

  const auto* st = static_cast<const std::uint32_t*>(buf[b_stats].mapped);
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

  drain(static_cast<const std::uint32_t*>(buf[b_brick_requests].mapped), brick_capacity,
        frame.level_count, result.brick_requests);
  drain(static_cast<const std::uint32_t*>(buf[b_node_requests].mapped), node_capacity, 0,
        result.node_requests);

  result.used_cache_slots.clear();
  const auto* used = static_cast<const std::uint32_t*>(buf[b_used].mapped);
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
  const Impl& m = *impl_;
  if (!m.configured) throw invalid_parameter("array", "backend is not configured");
  check(vkDeviceWaitIdle(m.ctx->device), "vkDeviceWaitIdle");
  std::size_t bytes = 0;
  Binding b = b_cache;
  switch (array) {
    case DeviceArray::cache:
      bytes = std::size_t(m.config.cache_slots) * m.slot_voxels * m.voxel_bytes;
      break;
    case DeviceArray::pages:
      bytes = std::size_t(m.config.page_entries) * 4;
      b = b_pages;
      break;
    case DeviceArray::page_offsets:
      bytes = (std::size_t(m.config.page_tables) + 1) * 4;
      b = b_page_offsets;
      break;
    case DeviceArray::nodes:
      bytes = std::size_t(m.config.node_words) * 4;
      b = b_nodes;
      break;
  }
  std::vector<std::byte> out(bytes);
  if (array == DeviceArray::cache) {
    const std::size_t brick_bytes = m.slot_voxels * m.voxel_bytes;
    for (std::uint32_t s = 0; s < m.config.cache_slots; ++s) {
      std::memcpy(out.data() + std::size_t(s) * brick_bytes, m.slot_address(s), brick_bytes);
    }
  } else if (bytes) {
    std::memcpy(out.data(), m.buf[b].mapped, bytes);
  }
  return out;
}

}  // namespace resoct::vk
