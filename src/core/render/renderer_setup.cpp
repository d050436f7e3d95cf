// Building a Renderer's engine from its source, backend and options (renderer_impl.hpp): the
// page table, brick cache, residency octree, loader and the backend's configuration.
#include <algorithm>
#include <limits>
#include <mutex>

#include "renderer_impl.hpp"
#include "resoct/base/error.hpp"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct {

namespace {

using detail::page_unmapped;
using detail::SharedEye;
using detail::SharedWishList;

const BrickSource& checked_source(const std::shared_ptr<const BrickSource>& s) {
  if (!s) throw invalid_parameter("source", "must not be null");
  return *s;
}

std::uint32_t slot_count_for(const RendererOptions& o, const BrickSource& s) {
  if (o.visible_slots != 0) return o.visible_slots;
  return std::min(s.volume().channels, kernel::RESOCT_MAX_SLOTS);
}

// The sparse page table's pool capacity (RendererOptions::page_pool_blocks).
std::uint32_t pool_blocks_for(const RendererOptions& o, const BrickHierarchy& h,
                              std::uint32_t slots) {
  const std::uint64_t total = PageTable::block_count(h, slots);
  const std::uint64_t slot_bytes = h.layout().padded_voxels() * voxel_size(h.volume().type);
  const std::uint64_t cache_slots = o.device_cache_bytes / slot_bytes;
  constexpr std::uint64_t kMax = kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS - 1u;
  std::uint64_t blocks = o.page_pool_blocks;
  if (blocks == 0) {
    blocks = std::min(total, cache_slots + std::max<std::uint64_t>(cache_slots / 2u, 64u));
    blocks = std::min(blocks, kMax);
  }
  if (blocks > kMax) {
    throw invalid_parameter("page_pool_blocks", std::to_string(blocks) + " exceeds the " +
                                                    std::to_string(kMax) +
                                                    " blocks 32-bit request keys address");
  }
  if (blocks < total && blocks <= cache_slots) {
    throw invalid_parameter("page_pool_blocks",
                            std::to_string(blocks) + " blocks must exceed the device cache's " +
                                std::to_string(cache_slots) + " slots (or cover all " +
                                std::to_string(total) +
                                " blocks); raise it or lower device_cache_bytes");
  }
  return std::uint32_t(blocks);
}

// Options are validated before the policies are made, so `policy` is one of the three. The
// published Octreemizer distance is the neighbourhood distance in bricks to the last frame's wish
// list tree; the camera variant measures from the eye in physical units.
std::unique_ptr<EvictionPolicy> make_policy(Eviction policy, const BrickHierarchy& h,
                                            const glm::dvec3* camera,
                                            std::shared_ptr<SharedWishList> wish) {
  if (policy == Eviction::lru) return std::make_unique<LruPolicy>();
  if (policy == Eviction::octreemizer) {
    return std::make_unique<OctreemizerPolicy>(
        h.level_count(), OctreemizerWeights{},
        [wish = std::move(wish)](BrickKey key) { return wish->distance(key); });
  }
  // Distances in physical units from the camera of the frame being rendered.
  return std::make_unique<OctreemizerPolicy>(
      h.level_count(), OctreemizerWeights{},
      [&h, camera](BrickKey key) { return brick_camera_distance(h, key, *camera); });
}

std::unique_ptr<EvictionPolicy> make_host_policy(Eviction policy, const BrickHierarchy& h,
                                                 std::shared_ptr<SharedEye> eye,
                                                 std::shared_ptr<SharedWishList> wish) {
  if (policy != Eviction::octreemizer_camera) return make_policy(policy, h, nullptr, wish);
  return std::make_unique<OctreemizerPolicy>(h.level_count(), OctreemizerWeights{},
                                             [&h, eye](BrickKey key) {
                                               glm::dvec3 e;
                                               {
                                                 std::lock_guard lock(eye->mutex);
                                                 e = eye->eye;
                                               }
                                               return brick_camera_distance(h, key, e);
                                             });
}

// Checked first, before any structure is built.
RendererOptions validated(RendererOptions o, const Backend* backend) {
  if (backend == nullptr) throw invalid_parameter("backend", "must not be null");
  o.validate();
  return o;
}

std::unique_ptr<Backend> named_backend(const RendererOptions& options) {
  options.validate();  // before creating a device for options that would be refused anyway
  return create_backend(options.backend, options.backend_options);
}

}  // namespace

Renderer::Renderer(std::shared_ptr<const BrickSource> source, RendererOptions options)
    : Renderer(std::move(source), named_backend(options), options) {}

Renderer::Renderer(std::shared_ptr<const BrickSource> source, std::unique_ptr<Backend> backend,
                   RendererOptions options)
    : impl_(std::make_unique<Impl>(std::move(source), std::move(backend), std::move(options))) {}

Renderer::Impl::Impl(std::shared_ptr<const BrickSource> source, std::unique_ptr<Backend> backend,
                     RendererOptions options)
    : source_(std::move(source)),
      options_(validated(std::move(options), backend.get())),
      hierarchy_(checked_source(source_).hierarchy()),
      layout_(hierarchy_.volume().extent, options_.leaf_size),
      pages_(hierarchy_, slot_count_for(options_, *source_),
             pool_blocks_for(options_, hierarchy_, slot_count_for(options_, *source_))),
      channels_(pages_.slot_count(), hierarchy_.volume().channels) {
  cache_ = std::make_unique<BrickCache>(
      hierarchy_.layout(), hierarchy_.volume().type, options_.device_cache_bytes, options_.ttl,
      make_policy(options_.eviction, hierarchy_, &camera_, wish_list_));
  // Residency means "sampling needs no cache miss": EMPTY and HOMOGENEOUS entries qualify as
  // well as MAPPED ones, so the traversal may use such a level without touching the cache.
  octree_ = std::make_unique<ResidencyOctree>(
      hierarchy_, layout_, pages_.slot_count(),
      [this](std::uint32_t slot, std::uint32_t level, glm::uvec3 brick) {
        return !page_unmapped(pages_.entry(PageAddress{slot, level, brick}));
      });
  loader_ = std::make_unique<BrickLoader>(
      source_, options_.loader_threads, options_.host_cache_bytes,
      make_host_policy(options_.host_eviction, hierarchy_, host_camera_, wish_list_),
      std::make_shared<const OctreeLayout>(layout_), options_.brick_errors);
  loader_->set_transient_retry(std::chrono::milliseconds(options_.retry_failed_after_ms));
  timepoint_ = source_->timepoint();
  timepoint_source_ = source_;
  backend_ = std::move(backend);
  config_.voxel_type = hierarchy_.volume().type;
  config_.padded_brick = hierarchy_.layout().padded_size();
  config_.cache_slots = cache_->slot_count();
  config_.page_pool_blocks = pages_.pool_block_count();
  config_.directory_entries = std::uint32_t(pages_.directory().size());
  config_.page_tables = pages_.table_count();
  config_.node_words = octree_->words().size();
  config_.brick_request_capacity = options_.brick_request_capacity;
  config_.node_request_capacity = options_.node_request_capacity;
  {
    // min(max_bricks x brick bytes, max_bytes) without overflowing the "unlimited" defaults.
    const std::uint64_t brick =
        hierarchy_.layout().padded_voxels() * voxel_size(hierarchy_.volume().type);
    const std::uint64_t b = options_.upload_budget.max_bricks;
    const std::uint64_t by_count =
        b > std::numeric_limits<std::uint64_t>::max() / brick ? ~0ull : b * brick;
    config_.upload_bytes_per_frame = std::min(by_count, options_.upload_budget.max_bytes);
  }
  backend_->configure(config_);
}

}  // namespace resoct
