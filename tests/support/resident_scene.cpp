#include "support/resident_scene.hpp"

#include <algorithm>
#include <cmath>

#include "resoct/base/error.hpp"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/render/visible_subtrees.hpp"
#include "resoct/sources/brick_error.hpp"

namespace resoct::test {

ResidentScene::ResidentScene(const BrickSource& source, std::vector<std::uint32_t> channels,
                             const ResidentOptions& options)
    : source_(source),
      layout_(source.hierarchy().volume().extent, options.leaf_size),
      channels_(std::uint32_t(channels.size()), source.hierarchy().volume().channels) {
  const BrickHierarchy& h = source.hierarchy();
  const VolumeDesc& vol = h.volume();
  const std::uint32_t slots = std::uint32_t(channels.size());
  // Everything may become resident: a pool block for every directory entry.
  pages_ = std::make_unique<PageTable>(
      h, slots,
      std::uint32_t(std::min<std::uint64_t>(PageTable::block_count(h, slots),
                                            kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS - 1u)));
  for (std::uint32_t s = 0; s < slots; ++s) channels_.assign(s, channels[s], *pages_);
  PageTable* pages = pages_.get();
  octree_ = std::make_unique<ResidencyOctree>(
      h, layout_, slots, [pages](std::uint32_t slot, std::uint32_t level, glm::uvec3 brick) {
        return kernel::resoct_page_state(pages->entry({slot, level, brick})) !=
               kernel::RESOCT_PAGE_STATE_UNMAPPED;
      });
  const std::size_t brick_bytes = h.layout().padded_voxels() * voxel_size(vol.type);

  struct Pending {
    std::uint32_t slot;
    std::size_t offset;
  };
  std::vector<Pending> pending;
  for (std::uint32_t s = 0; s < slots; ++s) {
    const std::uint32_t c = channels[s];
    const ValueRange range = vol.range(c);
    octree_->remap_slot(s, range);
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      if (options.level_resident && !options.level_resident(l)) continue;
      const LevelInfo& li = h.level(l);
      for (std::uint32_t z = 0; z < li.bricks.z; ++z) {
        for (std::uint32_t y = 0; y < li.bricks.y; ++y) {
          for (std::uint32_t x = 0; x < li.bricks.x; ++x) {
            const glm::uvec3 b(x, y, z);
            if (options.brick_resident && !options.brick_resident(l, b)) continue;
            const BrickKey key(l, c, b);
            const BrickMeta meta = source.brick_meta(key);
            const PageAddress a{s, l, b};
            // The loader's error code (HostBrick::error): level >= 1, measured on the voxels.
            const auto error_code = [&](std::span<const std::byte> voxels) {
              return options.brick_errors && l > 0
                         ? brick_error_code(brick_error_to_float(source.brick_error(key, voxels)))
                         : 0u;
            };
            if (meta.all_zero()) {
              pages_->set_empty(a);
            } else if (meta.constant && std::isfinite(meta.min)) {
              std::vector<std::byte> voxels(options.brick_errors && l > 0 ? brick_bytes : 0);
              if (!voxels.empty()) source.read_brick(key, voxels);
              pages_->set_homogeneous(a, meta.min, range, error_code(voxels));
            } else {
              const std::uint32_t cache_slot = std::uint32_t(pending.size());
              const std::size_t offset = voxels_.size();
              voxels_.resize(offset + brick_bytes);
              const std::span<std::byte> voxels(voxels_.data() + offset, brick_bytes);
              source.read_brick(key, voxels);
              pages_->set_mapped(a, cache_slot, error_code(voxels));
              pending.push_back({cache_slot, offset});
            }
            octree_->brick_added(s, l, b);
          }
        }
      }
    }
    if (options.metadata) {
      const std::uint32_t depth = std::min(options.metadata_depth, layout_.leaf_depth());
      const OctreeDepth& d = layout_.depth(depth);
      layout_.for_each_node(depth, NodeCoordRange{glm::uvec3(0), d.count},
                            [&](std::uint64_t node, const glm::uvec3&) {
                              const Box3 box = layout_.sampling_support(node);
                              if (box.empty()) return;
                              octree_->node_metadata(s, node, source.region_meta(c, box));
                            });
    }
  }
  for (const Pending& p : pending) {
    uploads_.push_back(
        {p.slot, std::span<const std::byte>(voxels_.data() + p.offset, brick_bytes)});
  }
  // Every block allocated (the pool holds them all): the kernel reports brick keys, never
  // block misses, so requests decode to bricks (decode()).
  for (std::uint32_t d = 0; d < pages_->directory().size() && d < pages_->max_blocks(); ++d)
    pages_->allocate_block(d);
  pages_->take_deltas();
  octree_->take_deltas();
}

void ResidentScene::upload(Backend& backend) const {
  const BrickHierarchy& h = source_.hierarchy();
  BackendConfig config;
  config.voxel_type = h.volume().type;
  config.padded_brick = h.layout().padded_size();
  config.cache_slots = std::max<std::uint32_t>(mapped_bricks(), 1u);
  config.page_pool_blocks = pages_->pool_block_count();
  config.directory_entries = std::uint32_t(pages_->directory().size());
  config.page_tables = pages_->table_count();
  config.node_words = octree_->words().size();
  backend.configure(config);
  FrameUpdate u;
  u.bricks = uploads_;
  u.pages_full = true;
  u.all_pages = pages_->pool();
  u.all_directory = pages_->directory();
  u.directory_offsets = pages_->directory_offsets();
  u.nodes_full = true;
  u.all_nodes = octree_->words();
  backend.update(u);
}

FrameTables ResidentScene::tables(const Scene& scene, const FrameOptions& options,
                                  float skip_min_samples) const {
  FrameTables t = build_frame_tables(scene, source_.hierarchy(), layout_, channels_, options);
  // As the Renderer does: residency-mode tables carry the octree's visible-subtree bits.
  build_visible_subtrees(*octree_, t, skip_min_samples);
  return t;
}

PageAddress ResidentScene::decode(std::uint32_t device_key) const {
  auto a = pages_->decode_device_key(device_key);
  if (!a) throw Error(ErrorCode::corrupt, "not a device key");
  return *a;
}

}  // namespace resoct::test
