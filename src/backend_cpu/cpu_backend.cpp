#include "resoct/cpu/cpu_backend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <new>
#include <string>

#include <omp.h>

#include "resoct/base/error.hpp"
#include "kernel_access.hpp"

namespace resoct::cpu::detail {

__thread const KernelContext* t_ctx = nullptr;

}  // namespace resoct::cpu::detail

namespace resoct::cpu {

namespace {

template <class T>
void resize_zeroed(std::vector<T>& v, std::size_t n, const char* what) {
  try {
    v.assign(n, T{});
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory, std::string("cpu backend: cannot allocate ") + what +
                                              " (" + std::to_string(n) + " elements)");
  }
}

}  // namespace

void register_backend() {
  static std::once_flag once;
  std::call_once(once, [] {
    resoct::register_backend("cpu", [](const BackendOptions& o) -> std::unique_ptr<Backend> {
      return std::make_unique<CpuBackend>(o.threads);
    });
  });
}

CpuBackend::CpuBackend(int threads) : threads_(threads) {}
CpuBackend::~CpuBackend() = default;

void CpuBackend::configure(const BackendConfig& config) {
  const glm::uvec3 p = config.padded_brick;
  if (p.x == 0 || p.y == 0 || p.z == 0) throw invalid_parameter("config", "padded_brick is 0");
  const std::size_t slot_voxels = std::size_t(p.x) * p.y * p.z;
  const std::size_t vb = voxel_size(config.voxel_type);
  if (config.cache_slots > 0 && slot_voxels * vb > (std::size_t(1) << 62) / config.cache_slots) {
    throw invalid_parameter("config", "cache pool byte size overflows");
  }
  check_page_table_config(config);
  if (config.node_words > (std::uint64_t(1) << 32)) {
    throw invalid_parameter("config", "node_words exceeds 2^32");
  }
  configured_ = false;
  config_ = config;
  voxel_bytes_ = vb;
  slot_voxels_ = slot_voxels;
  resize_zeroed(cache_,
                std::size_t(config.cache_slots) * slot_voxels * vb + detail::kCacheReadSlack,
                "brick cache");
  resize_zeroed(pages_, std::size_t(config.page_pool_blocks) * kernel::RESOCT_PAGE_BLOCK_ENTRIES,
                "page pool");
  resize_zeroed(directory_, config.directory_entries, "page directory");
  resize_zeroed(directory_offsets_, std::size_t(config.page_tables) + 1u, "page directory offsets");
  resize_zeroed(nodes_, std::size_t(config.node_words), "octree");
  used_words_ = (std::size_t(config.cache_slots) + 63u) / 64u;
  used_bits_ =
      std::make_unique<std::atomic<std::uint64_t>[]>(std::max<std::size_t>(used_words_, 1));
  for (std::size_t i = 0; i < used_words_; ++i) used_bits_[i].store(0);
  brick_requests_ = std::make_unique<RequestSet>(config.brick_request_capacity);
  node_requests_ = std::make_unique<RequestSet>(config.node_request_capacity);
  configured_ = true;
}

void CpuBackend::update(const FrameUpdate& u) {
  if (!configured_) throw invalid_parameter("update", "backend is not configured");
  const std::size_t brick_bytes = slot_voxels_ * voxel_bytes_;
  for (const BrickUpload& b : u.bricks) {
    if (b.cache_slot >= config_.cache_slots) {
      throw invalid_parameter("update", "cache slot " + std::to_string(b.cache_slot) +
                                            " outside the configured " +
                                            std::to_string(config_.cache_slots));
    }
    if (b.voxels.size() != brick_bytes) {
      throw invalid_parameter("update", "brick of " + std::to_string(b.voxels.size()) +
                                            " bytes, expected " + std::to_string(brick_bytes));
    }
    std::memcpy(cache_.data() + std::size_t(b.cache_slot) * brick_bytes, b.voxels.data(),
                brick_bytes);
  }
  const std::uint32_t pool_blocks = config_.page_pool_blocks;
  if (u.pages_full) {
    if (u.all_pages.size() > pages_.size()) {
      throw invalid_parameter("update", "full page pool of " + std::to_string(u.all_pages.size()) +
                                            " words, at most " + std::to_string(pages_.size()));
    }
    if (u.all_directory.size() != directory_.size()) {
      throw invalid_parameter("update",
                              "full page directory of " + std::to_string(u.all_directory.size()) +
                                  " entries, expected " + std::to_string(directory_.size()));
    }
    if (u.directory_offsets.size() != directory_offsets_.size()) {
      throw invalid_parameter("update", "directory_offsets has the wrong size");
    }
    for (std::uint32_t o : u.directory_offsets) {
      if (o > directory_.size()) throw invalid_parameter("update", "directory offset out of range");
    }
    for (std::uint32_t b : u.all_directory) {
      if (b >= pool_blocks) throw invalid_parameter("update", "directory names no pool block");
    }
  }
  for (const PageDelta& d : u.page_deltas) {
    if (d.index >= pages_.size()) throw invalid_parameter("update", "page delta out of range");
  }
  for (const PageDelta& d : u.directory_deltas) {
    if (d.index >= directory_.size() || d.value >= pool_blocks)
      throw invalid_parameter("update", "directory delta out of range");
  }
  if (u.pages_full) {
    std::copy(u.all_pages.begin(), u.all_pages.end(), pages_.begin());
    std::fill(pages_.begin() + std::ptrdiff_t(u.all_pages.size()), pages_.end(), 0u);
    std::copy(u.all_directory.begin(), u.all_directory.end(), directory_.begin());
    std::copy(u.directory_offsets.begin(), u.directory_offsets.end(), directory_offsets_.begin());
  }
  for (const PageDelta& d : u.page_deltas) pages_[d.index] = d.value;
  for (const PageDelta& d : u.directory_deltas) directory_[d.index] = d.value;
  if (u.nodes_full) {
    if (u.all_nodes.size() != nodes_.size()) {
      throw invalid_parameter("update", "full octree of " + std::to_string(u.all_nodes.size()) +
                                            " words, expected " + std::to_string(nodes_.size()));
    }
    std::copy(u.all_nodes.begin(), u.all_nodes.end(), nodes_.begin());
  }
  for (const OctreeWordDelta& d : u.node_deltas) {
    if (d.index >= nodes_.size()) throw invalid_parameter("update", "octree delta out of range");
    nodes_[d.index] = d.value;
  }
}

void CpuBackend::check_tables(const FrameTables& t) const {
  if (!configured_) throw invalid_parameter("tables", "backend is not configured");
  check_frame_tables(t, config_);
}

void CpuBackend::render(const FrameTables& tables, FrameResult& result) {
  const auto start = std::chrono::steady_clock::now();
  check_tables(tables);
  const kernel::ResoctFrame frame = tables.frame;
  detail::KernelContext c;
  c.nodes = nodes_.data();
  c.pages = pages_.data();
  c.directory = directory_.data();
  c.directory_offsets = directory_offsets_.data();
  c.slots = tables.slots.data();
  c.levels = tables.levels.data();
  c.depths = tables.depths.data();
  c.tf = tables.tf_luts.data();
  c.preint = tables.preint_tables.data();
  c.step_luts = tables.step_luts.data();
  c.visible_subtrees = tables.visible_subtrees.empty() ? nullptr : tables.visible_subtrees.data();
  c.fx = &tables.fx;
  c.cache = cache_.data();
  c.slot_voxels = slot_voxels_;
  c.type = config_.voxel_type;
  c.geometry = detail::BrickGeometry(glm::ivec3(config_.padded_brick));
  c.brick_bytes = slot_voxels_ * voxel_bytes_;
  c.brick_requests = brick_requests_.get();
  c.node_requests = node_requests_.get();
  c.used = used_bits_.get();

  if (result.image.width() != frame.width || result.image.height() != frame.height) {
    result.image = Image(frame.width, frame.height);
  }
  glm::vec4* pixels = result.image.pixels().data();
  const int threads = threads_ > 0 ? threads_ : omp_get_max_threads();
  // The effect mask picks the kernel specialization once per frame.
  const std::uint32_t mask = tables.fx.effects & (kernel::RESOCT_EFFECT_MASKS - 1u);
  const std::uint32_t fx = mask & kernel::RESOCT_EFFECT_ANY;
  const bool preint = (mask & kernel::RESOCT_EFFECT_PREINT) != 0u;
  const detail::RayTotals r =
      fx == 0u ? (preint ? detail::render_preint(c, frame, pixels, threads)
                         : detail::render_plain(c, frame, pixels, threads))
               : (preint ? detail::render_effects_preint(fx, c, frame, pixels, threads)
                         : detail::render_effects(fx, c, frame, pixels, threads));

  BackendStats& s = result.stats;
  s = BackendStats{};
  s.rays = std::uint64_t(frame.width) * frame.height;
  s.samples = r.samples;
  s.nodes_visited = r.nodes;
  s.brick_accesses = r.accesses;
  s.iterations = r.iterations;
  s.cap_hits = r.caps;
  s.request_inserts = r.requests;
  s.gradient_evals = r.gradients;
  s.shadow_rays = r.shadow_rays;
  s.distance_skipped = r.skipped;
  s.distance_marched = r.marched;

  // Brick keys name pool blocks, not levels (FrameResult::brick_requests).
  RequestBatch bricks = brick_requests_->drain();
  RequestBatch node_batch = node_requests_->drain();
  s.requests_dropped = bricks.dropped + node_batch.dropped;
  result.brick_requests = std::move(bricks.requests);
  result.node_requests = std::move(node_batch.requests);

  result.used_cache_slots.clear();
  for (std::size_t w = 0; w < used_words_; ++w) {
    std::uint64_t bits = used_bits_[w].exchange(0, std::memory_order_relaxed);
    while (bits != 0) {
      const int b = __builtin_ctzll(bits);
      result.used_cache_slots.push_back(std::uint32_t(w * 64u + std::size_t(b)));
      bits &= bits - 1u;
    }
  }
  s.ms_render =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace resoct::cpu
