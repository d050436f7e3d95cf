// Per-sample traversal cost and frame time of the three render modes side by side, CPU backend,
// everything resident, 256×256 image, one thread (so ns/iteration is the kernel's cost, not the
// machine's parallelism).
//
//   BM_Traverse/<dataset>/<channels>/<mode>
//     dataset 0 = procedural:tubes:256x256x256 (1 channel; 4 and 16 use tubes:...:16 channels)
//     dataset 1 = procedural:cells:256x256x40 (channels 1, 4, 16 of the 16)
//     mode 0 = residency, 1 = pagetable, 2 = octree
// Counters (per frame): ms_frame; ns_per_iteration = frame time / positions visited (sampled or
// skipped from); ns_per_sample = frame time / composited samples; samples_per_ray,
// iterations_per_ray, nodes_per_ray, brick_accesses_per_ray, skipped_fraction = distance skipped
// / (skipped + marched). Every level is resident and a channel may use any of them
// (coarsest_level = the last), so the octree mode walks its whole path of bricks from the
// coarsest level down, as paper 000's octree baseline does; a LOD error of 1e-6 px makes every
// sample's target level 0, so all modes sample the same voxels and render the same image.
// Set-up (loading every brick of every level and the leaf metadata) is paid once per dataset and
// channel count, outside the timing. RESOCT_BENCH_SMOKE=1 (ctest) shrinks to 48³ / 64×64×40
// and 32² images.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "resoct/engine/channel_map.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/render/frame_tables.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/engine/residency_octree.hpp"

namespace {

using namespace resoct;

bool smoke() {
  const char* v = std::getenv("RESOCT_BENCH_SMOKE");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

struct Rig {
  std::unique_ptr<BrickSource> source;
  OctreeLayout layout;
  std::unique_ptr<ChannelMap> channels;
  std::unique_ptr<PageTable> pages;
  std::unique_ptr<ResidencyOctree> octree;
  std::unique_ptr<cpu::CpuBackend> backend;
  Scene scene;
};

// Loads every brick of every level of the first `n` channels (slot i = channel i) and the leaf
// metadata, then uploads everything to a fresh CPU backend.
std::unique_ptr<Rig> make_rig(const std::string& spec, std::uint32_t n) {
  auto rig = std::make_unique<Rig>();
  rig->source = make_procedural_source(spec);
  const BrickHierarchy& h = rig->source->hierarchy();
  const VolumeDesc& vol = h.volume();
  rig->layout = OctreeLayout(vol.extent, glm::uvec3(16));
  rig->channels = std::make_unique<ChannelMap>(n, vol.channels);
  const std::uint64_t blocks = PageTable::block_count(h, n);
  rig->pages = std::make_unique<PageTable>(h, n, std::uint32_t(blocks));
  // Every block allocated, as for data that is resident everywhere.
  for (std::uint32_t d = 0; d < blocks; ++d) rig->pages->allocate_block(d);
  for (std::uint32_t s = 0; s < n; ++s) rig->channels->assign(s, s, *rig->pages);
  PageTable* pages = rig->pages.get();
  rig->octree = std::make_unique<
      ResidencyOctree>(h, rig->layout, n, [pages](std::uint32_t s, std::uint32_t l, glm::uvec3 b) {
    return kernel::resoct_page_state(pages->entry({s, l, b})) != kernel::RESOCT_PAGE_STATE_UNMAPPED;
  });
  const std::size_t brick_bytes = h.layout().padded_voxels() * voxel_size(vol.type);
  std::vector<std::byte> voxels;
  std::vector<std::uint32_t> slots;
  for (std::uint32_t s = 0; s < n; ++s) {
    const ValueRange range = vol.range(s);
    rig->octree->remap_slot(s, range);
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const LevelInfo& level = h.level(l);
      for (std::uint32_t z = 0; z < level.bricks.z; ++z) {
        for (std::uint32_t y = 0; y < level.bricks.y; ++y) {
          for (std::uint32_t x = 0; x < level.bricks.x; ++x) {
            const glm::uvec3 b(x, y, z);
            const BrickKey key(l, s, b);
            const BrickMeta meta = rig->source->brick_meta(key);
            if (meta.all_zero()) {
              rig->pages->set_empty({s, l, b});
            } else if (meta.constant && std::isfinite(meta.min)) {
              rig->pages->set_homogeneous({s, l, b}, meta.min, range);
            } else {
              const std::uint32_t slot = std::uint32_t(slots.size());
              voxels.resize(voxels.size() + brick_bytes);
              rig->source->read_brick(
                  key, std::span<std::byte>(voxels.data() + std::size_t(slot) * brick_bytes,
                                            brick_bytes));
              rig->pages->set_mapped({s, l, b}, slot);
              slots.push_back(slot);
            }
            rig->octree->brick_added(s, l, b);
          }
        }
      }
    }
    const std::uint32_t leaf = rig->layout.leaf_depth();
    rig->layout.for_each_node(
        leaf, NodeCoordRange{glm::uvec3(0), rig->layout.depth(leaf).count},
        [&](std::uint64_t node, const glm::uvec3&) {
          Box3 box = rig->layout.node_box(node);
          if (box.empty()) return;
          // Cover the trilinear support (one voxel around the node).
          box.lo = glm::max(box.lo - glm::i64vec3(1), glm::i64vec3(0));
          box.hi = glm::min(box.hi + glm::i64vec3(1), glm::i64vec3(vol.extent));
          rig->octree->node_metadata(s, node, rig->source->region_meta(s, box));
        });
  }
  rig->backend = std::make_unique<cpu::CpuBackend>(1);
  BackendConfig config;
  config.voxel_type = vol.type;
  config.padded_brick = h.layout().padded_size();
  config.cache_slots = std::max<std::uint32_t>(std::uint32_t(slots.size()), 1u);
  config.page_pool_blocks = rig->pages->pool_block_count();
  config.directory_entries = std::uint32_t(rig->pages->directory().size());
  config.page_tables = rig->pages->table_count();
  config.node_words = rig->octree->words().size();
  rig->backend->configure(config);
  std::vector<BrickUpload> uploads;
  for (std::uint32_t s : slots) {
    uploads.push_back(
        {s, std::span<const std::byte>(voxels.data() + std::size_t(s) * brick_bytes, brick_bytes)});
  }
  FrameUpdate u;
  u.bricks = uploads;
  u.pages_full = true;
  u.all_pages = rig->pages->pool();
  u.all_directory = rig->pages->directory();
  u.directory_offsets = rig->pages->directory_offsets();
  u.nodes_full = true;
  u.all_nodes = rig->octree->words();
  rig->backend->update(u);

  Scene& sc = rig->scene;
  sc.camera.eye = {1.6, 1.2, 1.9};
  sc.camera.target = {0.5, 0.5 * box_extent(vol).y, 0.5 * box_extent(vol).z};
  sc.viewport = smoke() ? Viewport{32, 32} : Viewport{256, 256};
  sc.step_scale = 1.0;
  sc.lod_error_px = 1e-6;
  for (std::uint32_t s = 0; s < n; ++s) {
    ChannelSettings c;
    c.channel = s;
    c.finest_level = 0;
    c.coarsest_level = h.level_count() - 1;
    const double hue = double(s) / double(n);
    c.tf = TransferFunction({{0.0, {1, 1, 1, 0}},
                             {0.1, {1, 1, 1, 0}},
                             {0.4, {hue, 1.0 - hue, 0.5, 0.05}},
                             {1.0, {1.0, hue, 1.0 - hue, 0.3}}});
    sc.channels.push_back(c);
  }
  return rig;
}

// One rig at a time (benchmarks run dataset by dataset, modes innermost), so memory stays that
// of the largest single configuration.
Rig& rig_for(int dataset, std::uint32_t channels) {
  static std::pair<int, std::uint32_t> key{-1, 0};
  static std::unique_ptr<Rig> rig;
  if (!rig || key != std::pair<int, std::uint32_t>{dataset, channels}) {
    rig.reset();
    // The ctest smoke run (RESOCT_BENCH_SMOKE=1) only checks that the program works.
    const std::string size = smoke() ? "48x48x48" : "256x256x256";
    const std::string spec =
        dataset == 0
            ? "procedural:tubes:" + size + (channels == 1 ? "" : ":16")
            : std::string("procedural:cells:") + (smoke() ? "64x64x40" : "256x256x40") + ":16";
    rig = make_rig(spec, channels);
    key = {dataset, channels};
  }
  return *rig;
}

void BM_Traverse(benchmark::State& state) {
  const int dataset = int(state.range(0));
  const auto channels = std::uint32_t(state.range(1));
  const auto mode = RenderMode(std::uint32_t(state.range(2)));
  Rig& rig = rig_for(dataset, channels);
  FrameOptions o;
  o.mode = mode;
  const FrameTables tables =
      build_frame_tables(rig.scene, rig.source->hierarchy(), rig.layout, *rig.channels, o);
  FrameResult result;
  BackendStats total;
  std::int64_t frames = 0;
  for (auto _ : state) {
    rig.backend->render(tables, result);
    benchmark::DoNotOptimize(result.image.pixels().data());
    benchmark::ClobberMemory();
    total.rays += result.stats.rays;
    total.samples += result.stats.samples;
    total.iterations += result.stats.iterations;
    total.nodes_visited += result.stats.nodes_visited;
    total.brick_accesses += result.stats.brick_accesses;
    total.distance_skipped += result.stats.distance_skipped;
    total.distance_marched += result.stats.distance_marched;
    total.ms_render += result.stats.ms_render;
    ++frames;
  }
  const double f = double(frames);
  const double rays = double(total.rays);
  state.counters["ms_frame"] = total.ms_render / f;
  state.counters["ns_per_iteration"] = total.ms_render * 1e6 / double(total.iterations);
  state.counters["ns_per_sample"] =
      total.samples > 0 ? total.ms_render * 1e6 / double(total.samples) : 0.0;
  state.counters["samples_per_ray"] = double(total.samples) / rays;
  state.counters["iterations_per_ray"] = double(total.iterations) / rays;
  state.counters["nodes_per_ray"] = double(total.nodes_visited) / rays;
  state.counters["brick_accesses_per_ray"] = double(total.brick_accesses) / rays;
  const double dist = total.distance_skipped + total.distance_marched;
  state.counters["skipped_fraction"] = dist > 0 ? total.distance_skipped / dist : 0.0;
  state.SetItemsProcessed(std::int64_t(total.iterations));
  state.SetLabel(std::string(to_string(mode)));
}

BENCHMARK(BM_Traverse)
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (int dataset : {0, 1}) {
        for (int channels : {1, 4, 16}) {
          for (int mode : {0, 1, 2}) b->Args({dataset, channels, mode});
        }
      }
    })
    ->ArgNames({"dataset", "channels", "mode"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
