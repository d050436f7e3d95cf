// Delta uploads through the whole frame loop on the Vulkan backend: many frames with a device
// cache far smaller than the working set (evictions), the scene's channels swapped in and out of
// fewer slots (remaps clear page tables and octree slots), and a staging ring of two bricks (every
// update is split over several submissions). After every frame the device arrays read back must
// equal the host state: page pool, directory and offsets, octree words, and every occupied cache
// slot holding exactly the padded voxels of the brick the host cache says it holds. A second run
// uses a page-table pool smaller than the table's blocks, so block misses allocate blocks and
// the pool is reclaimed, and ends converged with the CPU backend's image.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "vulkan_test_util.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
#include "support/vulkan_required.hpp"

namespace resoct::test {
namespace {

template <class T>
std::vector<T> words_of(const std::vector<std::byte>& bytes) {
  std::vector<T> w(bytes.size() / sizeof(T));
  std::memcpy(w.data(), bytes.data(), w.size() * sizeof(T));
  return w;
}

// Compares every device array with the renderer's host state; returns the occupied slots.
std::size_t expect_device_matches_host(const Renderer& r, const vk::VulkanBackend& gpu,
                                       const std::string& what) {
  // The device pool: the host's used prefix, UNMAPPED beyond it.
  std::vector<std::uint32_t> pool = inspect::page_table(r).pool();
  pool.resize(
      std::size_t(inspect::page_table(r).pool_block_count()) * kernel::RESOCT_PAGE_BLOCK_ENTRIES,
      0u);
  EXPECT_EQ(words_of<std::uint32_t>(gpu.debug_read(vk::DeviceArray::pages)), pool) << what;
  EXPECT_EQ(words_of<std::uint32_t>(gpu.debug_read(vk::DeviceArray::directory)),
            inspect::page_table(r).directory())
      << what;
  EXPECT_EQ(words_of<std::uint32_t>(gpu.debug_read(vk::DeviceArray::directory_offsets)),
            inspect::page_table(r).directory_offsets())
      << what;
  const auto& words = inspect::octree(r).words();
  EXPECT_EQ(words_of<std::uint32_t>(gpu.debug_read(vk::DeviceArray::nodes)),
            std::vector<std::uint32_t>(words.begin(), words.end()))
      << what;
  const std::vector<std::byte> cache = gpu.debug_read(vk::DeviceArray::cache);
  const BrickHierarchy& h = r.hierarchy();
  const std::size_t brick_bytes =
      std::size_t(h.layout().padded_voxels()) * voxel_size(h.volume().type);
  std::vector<std::byte> expected(brick_bytes);
  std::size_t occupied = 0;
  for (std::uint32_t s = 0; s < inspect::cache(r).slot_count(); ++s) {
    const auto key = inspect::cache(r).key_of(s);
    if (!key) continue;
    ++occupied;
    r.source().read_brick(*key, expected);
    EXPECT_EQ(
        std::memcmp(cache.data() + std::size_t(s) * brick_bytes, expected.data(), brick_bytes), 0)
        << what << ": cache slot " << s << " level " << key->level() << " channel "
        << key->channel();
  }
  return occupied;
}

TEST(VulkanDeltaUploads, ManyFramesWithEvictionAndRemapsMatchTheHostState) {
  if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  BrickLayout layout;
  layout.brick_size = glm::uvec3(8);
  layout.halo = 1;
  auto source = std::make_shared<ProceduralSource>("procedural:cells:64x64x16:16", layout);
  const std::size_t brick_bytes = std::size_t(layout.padded_voxels()) * 2;  // u16
  // A ring of two bricks: uploads, full tables and delta lists all split over submissions.
  register_backend("vulkan-small-ring", [brick_bytes](const BackendOptions& o) {
    auto b = std::make_unique<vk::VulkanBackend>(o);
    b->debug_limit_staging_ring(2 * brick_bytes);
    return std::unique_ptr<Backend>(std::move(b));
  });
  RendererOptions o;
  o.backend = "vulkan-small-ring";
  o.backend_options.validation = true;
  o.loader_threads = 0;
  o.visible_slots = 3;
  o.leaf_size = glm::uvec3(8);
  o.device_cache_bytes = 24 * brick_bytes;  // far below the working set
  o.upload_budget = UploadBudget{6, ~0ull};
  o.ttl = 1;
  Renderer r(source, o);
  auto* gpu = dynamic_cast<vk::VulkanBackend*>(&inspect::backend(r));
  ASSERT_NE(gpu, nullptr);

  Scene base = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/cells.json");
  base.viewport = Viewport{20, 20};
  ASSERT_FALSE(base.channels.empty());
  // Channel sets per phase: three slots shared by up to seven channels.
  const std::vector<std::vector<std::uint32_t>> phases = {
      {0, 1, 2}, {0, 1, 2}, {3, 1}, {3, 4, 5}, {6}, {0, 6, 2}, {1, 4, 5}, {7, 0, 3}};
  std::uint64_t evictions = 0, uploads = 0, remaps = 0, page_deltas = 0, node_deltas = 0,
                full_pages = 0;
  std::size_t occupied = 0;
  std::vector<std::optional<std::uint32_t>> slot_channel(3);
  constexpr int kFrames = 32;
  for (int frame = 0; frame < kFrames; ++frame) {
    Scene s = base;
    s.channels.clear();
    for (std::uint32_t c : phases[std::size_t(frame / 4) % phases.size()]) {
      ChannelSettings ch = base.channels[0];
      ch.channel = c;
      ch.importance = std::int32_t(c);
      s.channels.push_back(ch);
    }
    // Orbit the camera so that the visible bricks change every frame.
    const double a = 0.4 * frame;
    s.camera.eye = {0.5 + 0.9 * std::cos(a), 0.5 + 0.9 * std::sin(a), 0.7};
    const FrameReport rep = r.render_frame(s);
    evictions += rep.stats.evictions;
    uploads += rep.stats.bricks_uploaded;
    for (std::uint32_t slot = 0; slot < 3; ++slot) {
      const auto c = inspect::channel_map(r).channel(slot);
      if (slot_channel[slot] && c != slot_channel[slot]) ++remaps;
      slot_channel[slot] = c;
    }
    page_deltas += rep.stats.page_deltas;
    full_pages += rep.stats.pages_full ? 1u : 0u;
    node_deltas += rep.stats.node_deltas;
    occupied =
        std::max(occupied, expect_device_matches_host(r, *gpu, "frame " + std::to_string(frame)));
    if (HasFailure()) break;
  }
  std::printf(
      "[ vulkan ] %d frames: %llu bricks uploaded, %llu evictions, %llu remaps, %llu page "
      "deltas, %llu octree words, %llu full page tables, up to %zu occupied slots\n",
      kFrames, static_cast<unsigned long long>(uploads), static_cast<unsigned long long>(evictions),
      static_cast<unsigned long long>(remaps), static_cast<unsigned long long>(page_deltas),
      static_cast<unsigned long long>(node_deltas), static_cast<unsigned long long>(full_pages),
      occupied);
  // The run must have exercised what it claims to.
  EXPECT_GT(uploads, 3u * 24u);
  EXPECT_GT(evictions, 0u);
  EXPECT_GE(remaps, 4u);
  EXPECT_GT(page_deltas, 0u);
  EXPECT_GT(node_deltas, 0u);
  expect_no_validation_messages(*gpu);
}

TEST(VulkanDeltaUploads, BlockAllocationAndReclaimMatchTheHostStateAndConverge) {
  if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  // 4^3 bricks over 512^3: level 0 is 128^3 bricks in 8^3 blocks, 589 blocks over all levels.
  BrickLayout layout;
  layout.brick_size = glm::uvec3(4);
  layout.halo = 1;
  auto source = std::make_shared<ProceduralSource>("procedural:sphere:512x512x512", layout);
  const std::uint64_t slot_bytes = layout.padded_voxels() * voxel_size(source->volume().type);
  vk::register_backend();
  RendererOptions o;
  o.backend = "vulkan";
  o.backend_options.validation = true;
  o.loader_threads = 0;
  o.leaf_size = glm::uvec3(16);
  o.device_cache_bytes = 16 * slot_bytes;
  // The orbit below touches about 23 of the 589 blocks, so a pool just above the 16 cache slots
  // must reclaim.
  o.page_pool_blocks = 17;
  ASSERT_EQ(PageTable::block_count(source->hierarchy(), 1), 589u);
  Renderer r(source, o);
  auto* gpu = dynamic_cast<vk::VulkanBackend*>(&inspect::backend(r));
  ASSERT_NE(gpu, nullptr);
  Scene s = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
  s.viewport = Viewport{16, 16};
  std::uint64_t misses = 0, freed = 0;
  std::vector<std::uint32_t> last_dir = inspect::page_table(r).directory();
  for (int frame = 0; frame < 16; ++frame) {
    const double a = 0.7 * frame;
    // Close to the volume: the finest levels of the blocks near the eye are needed.
    s.camera.eye = {0.5 + 0.7 * std::cos(a), 0.5 + 0.7 * std::sin(a), 0.55};
    const FrameReport rep = r.render_frame(s);
    misses += rep.stats.block_misses;
    const auto& dir = inspect::page_table(r).directory();
    for (std::size_t d = 0; d < dir.size(); ++d) freed += last_dir[d] != 0 && dir[d] == 0 ? 1 : 0;
    last_dir = dir;
    expect_device_matches_host(r, *gpu, "frame " + std::to_string(frame));
    if (HasFailure()) break;
  }
  EXPECT_GT(misses, 0u);
  EXPECT_GT(freed, 0u) << "the pool was never reclaimed";
  // Converges at a still view (a working set within the 16 slots), with the image of the CPU
  // backend run the same way.
  s.camera.eye = {1.6, 1.3, 1.9};
  s.viewport = Viewport{8, 8};
  const ConvergeReport done = r.render_until_converged(s, 48);
  ASSERT_TRUE(done.converged) << done.frames << " frames";
  expect_device_matches_host(r, *gpu, "converged");
  cpu::register_backend();
  RendererOptions oc = o;
  oc.backend = "cpu";
  oc.backend_options = BackendOptions{};
  oc.backend_options.threads = 1;
  Renderer rc(source, oc);
  const ConvergeReport cpu_done = rc.render_until_converged(s, 48);
  ASSERT_TRUE(cpu_done.converged);
  const ImageDiff d = compare_images(done.last.image, cpu_done.last.image);
  for (int ch = 0; ch < 4; ++ch) EXPECT_LE(d.max_abs[ch], 2e-3) << "channel " << ch;
  expect_no_validation_messages(*gpu);
}

}  // namespace
}  // namespace resoct::test
