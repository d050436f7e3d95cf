// Device state of the Vulkan backend: after many random updates (full arrays, page and octree
// deltas, brick uploads) the device arrays read back equal a host mirror; bad input and unknown
// devices fail with the documented errors.
#include <cstring>
#include <random>
#include <vector>

#include "vulkan_test_util.hpp"
#include "support/expect_error.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/scene/scene.hpp"
#include "support/vulkan_required.hpp"

namespace resoct::test {
namespace {

template <class T>
std::vector<T> as_words(const std::vector<std::byte>& bytes) {
  std::vector<T> w(bytes.size() / sizeof(T));
  std::memcpy(w.data(), bytes.data(), w.size() * sizeof(T));
  return w;
}

void check_random_updates(vk::VulkanBackend& gpu, VoxelType type, std::uint32_t seed,
                          std::uint64_t chunk_limit) {
  gpu.debug_limit_cache_buffer(chunk_limit);
  BackendConfig cfg;
  cfg.voxel_type = type;
  cfg.padded_brick = {5, 3, 7};  // odd sizes: u8/u16 bricks straddle 32-bit words
  cfg.cache_slots = 13;
  cfg.page_pool_blocks = 3;  // 3 x 4096 pool words
  cfg.directory_entries = 777;
  cfg.page_tables = 6;
  cfg.node_words = 1001;
  cfg.brick_request_capacity = 100;
  cfg.node_request_capacity = 50;
  gpu.configure(cfg);

  const std::size_t brick_bytes = 5u * 3u * 7u * voxel_size(type);
  std::vector<std::byte> cache(cfg.cache_slots * brick_bytes, std::byte{0});
  std::vector<std::uint32_t> pages(cfg.page_pool_blocks * 4096u, 0),
      offsets(cfg.page_tables + 1u, 0);
  std::vector<std::uint32_t> dir(cfg.directory_entries, 0);
  std::vector<std::uint32_t> nodes(cfg.node_words, 0);
  // configure() leaves every array zero.
  EXPECT_EQ(gpu.debug_read(vk::DeviceArray::cache), cache);
  EXPECT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::pages)), pages);
  EXPECT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::directory)), dir);
  EXPECT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::nodes)), nodes);

  std::mt19937 rng(seed);
  auto pick = [&rng](std::size_t n) { return std::uint32_t(rng() % n); };
  for (int round = 0; round < 60; ++round) {
    FrameUpdate u;
    std::vector<std::vector<std::byte>> brick_data;
    std::vector<BrickUpload> uploads;
    std::vector<PageDelta> pd, dd;
    std::vector<OctreeWordDelta> nd;
    std::vector<std::uint32_t> all_pages, all_dir, all_offsets, all_nodes;
    const int nb = int(rng() % 4);
    for (int i = 0; i < nb; ++i) {
      std::vector<std::byte> v(brick_bytes);
      for (auto& b : v) b = std::byte(rng() & 0xFFu);
      brick_data.push_back(std::move(v));
    }
    for (const auto& v : brick_data) {
      const std::uint32_t slot = pick(cfg.cache_slots);
      uploads.push_back({slot, v});
      std::memcpy(cache.data() + slot * brick_bytes, v.data(), brick_bytes);
    }
    if (round % 17 == 0) {
      // A prefix of the pool (the rest must read 0), the whole directory, the offsets.
      all_pages.resize(pick(pages.size() + 1));
      for (auto& p : all_pages) p = std::uint32_t(rng());
      all_dir.resize(dir.size());
      for (auto& d : all_dir) d = pick(cfg.page_pool_blocks);
      all_offsets.resize(offsets.size());
      for (auto& o : all_offsets) o = pick(dir.size() + 1);
      std::fill(pages.begin(), pages.end(), 0u);
      std::copy(all_pages.begin(), all_pages.end(), pages.begin());
      dir = all_dir;
      offsets = all_offsets;
      u.pages_full = true;
      u.all_pages = all_pages;
      u.all_directory = all_dir;
      u.directory_offsets = all_offsets;
    }
    if (round % 23 == 5) {
      all_nodes.resize(nodes.size());
      for (auto& w : all_nodes) w = std::uint32_t(rng());
      nodes = all_nodes;
      u.nodes_full = true;
      u.all_nodes = all_nodes;
    }
    for (int i = int(rng() % 40); i > 0; --i) {
      PageDelta d{pick(pages.size()), std::uint32_t(rng())};
      pd.push_back(d);
      pages[d.index] = d.value;  // later deltas of the same index win
    }
    for (int i = int(rng() % 40); i > 0; --i) {
      PageDelta d{pick(dir.size()), pick(cfg.page_pool_blocks)};
      dd.push_back(d);
      dir[d.index] = d.value;
    }
    for (int i = int(rng() % 40); i > 0; --i) {
      OctreeWordDelta d{pick(nodes.size()), std::uint32_t(rng())};
      nd.push_back(d);
      nodes[d.index] = d.value;
    }
    u.bricks = uploads;
    u.page_deltas = pd;
    u.directory_deltas = dd;
    u.node_deltas = nd;
    gpu.update(u);
    if (round % 10 == 9) {
      ASSERT_EQ(gpu.debug_read(vk::DeviceArray::cache), cache) << "round " << round;
      ASSERT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::pages)), pages);
      ASSERT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::directory)), dir);
      ASSERT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::directory_offsets)),
                offsets);
      ASSERT_EQ(as_words<std::uint32_t>(gpu.debug_read(vk::DeviceArray::nodes)), nodes);
    }
  }
}

TEST(VulkanState, RandomDeltasAndUploadsMatchTheHostArrays) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  check_random_updates(*gpu, VoxelType::u8, 1, 0);
  check_random_updates(*gpu, VoxelType::u16, 2, 0);
  check_random_updates(*gpu, VoxelType::f32, 3, 0);
  // 13 slots split over 7 cache buffers of two bricks each.
  check_random_updates(*gpu, VoxelType::u8, 4, 2 * 105 + 3);
  check_random_updates(*gpu, VoxelType::u16, 5, 2 * 210 + 3);
  check_random_updates(*gpu, VoxelType::f32, 6, 2 * 420 + 3);
  expect_no_validation_messages(*gpu);
}

TEST(VulkanState, BadUpdatesAndTablesAreRejected) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  FrameUpdate none;
  EXPECT_RESOCT_ERROR(gpu->update(none), ErrorCode::invalid_argument, "update");
  BackendConfig cfg;
  cfg.padded_brick = {4, 4, 4};
  cfg.cache_slots = 2;
  cfg.page_pool_blocks = 1;
  cfg.directory_entries = 8;
  cfg.page_tables = 1;
  cfg.node_words = 8;
  gpu->configure(cfg);
  std::vector<std::byte> wrong(10);
  const BrickUpload up{0, wrong};
  FrameUpdate u;
  u.bricks = {&up, 1};
  EXPECT_RESOCT_ERROR(gpu->update(u), ErrorCode::invalid_argument, "update");
  const PageDelta far{4096, 1};
  FrameUpdate v;
  v.page_deltas = {&far, 1};
  EXPECT_RESOCT_ERROR(gpu->update(v), ErrorCode::invalid_argument, "page delta");
  for (const PageDelta bad : {PageDelta{8, 0}, PageDelta{0, 1}}) {
    FrameUpdate w;
    w.directory_deltas = {&bad, 1};
    EXPECT_RESOCT_ERROR(gpu->update(w), ErrorCode::invalid_argument, "directory delta");
  }
  FrameTables t;
  FrameResult r;
  EXPECT_RESOCT_ERROR(gpu->render(t, r), ErrorCode::invalid_argument, "tables");
  cfg.padded_brick = {0, 4, 4};
  EXPECT_RESOCT_ERROR(gpu->configure(cfg), ErrorCode::invalid_argument, "config");
  // 20 slots of one 64-byte brick per buffer need more than 8 buffers.
  cfg.padded_brick = {4, 4, 4};
  cfg.cache_slots = 20;
  gpu->debug_limit_cache_buffer(64);
  EXPECT_RESOCT_ERROR(gpu->configure(cfg), ErrorCode::out_of_memory, "buffers");
  expect_no_validation_messages(*gpu);
}

// Render pipelines are cached per specialization-constant variant: the same configuration reuses
// its pipeline, another brick size compiles a second one, and returning to the first compiles
// nothing and renders the same image.
TEST(VulkanState, PipelineVariantsAreCompiledOnceAndReused) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  auto layout = [](std::uint32_t brick) {
    BrickLayout l;
    l.brick_size = glm::uvec3(brick);
    l.halo = 1;
    return l;
  };
  Scene scene = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/sphere.json");
  scene.viewport = Viewport{12, 10};
  ProceduralSource src8("procedural:sphere:16x16x16", layout(8));
  ProceduralSource src4("procedural:sphere:16x16x16", layout(4));
  ResidentScene rs8(src8, {0});
  ResidentScene rs4(src4, {0});
  EXPECT_EQ(gpu->debug_pipeline_count(), 0u);  // built lazily by the first render
  const FrameResult first = render_on(*gpu, rs8, scene, {});
  EXPECT_GT(first.stats.samples, 0u);
  render_on(*gpu, rs8, scene, {});
  EXPECT_EQ(gpu->debug_pipeline_count(), 1u);
  render_on(*gpu, rs4, scene, {});
  EXPECT_EQ(gpu->debug_pipeline_count(), 2u);
  const FrameResult again = render_on(*gpu, rs8, scene, {});
  EXPECT_EQ(gpu->debug_pipeline_count(), 2u);
  EXPECT_EQ(again.image.pixels(), first.image.pixels());
  expect_no_validation_messages(*gpu);
}

TEST(VulkanState, UnknownDeviceNameIsADeviceError) {
  if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  BackendOptions o;
  o.device = "no-such-gpu-xyz";
  EXPECT_RESOCT_ERROR(vk::VulkanBackend{o}, ErrorCode::device, "device");
  o.device = "999";
  EXPECT_RESOCT_ERROR(vk::VulkanBackend{o}, ErrorCode::device, "device");
}

TEST(VulkanState, RegisteredFactorySelectsByNameAndIndex) {
  const auto devices = vk::list_devices();
  if (devices.empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  vk::register_backend();
  BackendOptions o;
  o.validation = true;
  o.device = "0";
  auto b = create_backend("vulkan", o);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->name(), "vulkan");
  auto* vb = dynamic_cast<vk::VulkanBackend*>(b.get());
  ASSERT_NE(vb, nullptr);
  EXPECT_EQ(vb->device_name(), devices[0].name);
  // A lower-case substring of the name selects the same device.
  std::string sub = devices[0].name.substr(0, 4);
  for (char& ch : sub) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  o.device = sub;
  vk::VulkanBackend by_name(o);
  EXPECT_NE(by_name.device_name().find(devices[0].name.substr(0, 4)), std::string::npos);
  expect_no_validation_messages(*vb);
  expect_no_validation_messages(by_name);
}

}  // namespace
}  // namespace resoct::test
