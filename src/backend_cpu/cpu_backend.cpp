#include "resoct/cpu/cpu_backend.hpp"

#include <algorithm>
#include <array>
#include <utility>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <new>
#include <string>

#include <omp.h>

#include "resoct/error.hpp"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"

namespace resoct::cpu::detail {

// Everything the kernel's accessors read during one render(). One process-wide instance, set
// under g_render_mutex: a plain global costs nothing per access, unlike a thread_local in a
// shared library.
struct KernelContext {
  const std::uint32_t* nodes = nullptr;
  const std::uint32_t* pages = nullptr;
  const std::uint32_t* page_offsets = nullptr;
  const kernel::ResoctSlotInfo* slots = nullptr;
  const kernel::ResoctLevelInfo* levels = nullptr;
  const kernel::ResoctDepthInfo* depths = nullptr;
  const glm::vec4* tf = nullptr;
  const std::byte* cache = nullptr;
  std::size_t slot_voxels = 0;
  VoxelType type = VoxelType::u8;
  glm::ivec3 padded{1};
  RequestSet* brick_requests = nullptr;
  RequestSet* node_requests = nullptr;
  std::atomic<std::uint64_t>* used = nullptr;
};

KernelContext g_ctx;
std::mutex g_render_mutex;

template <class T>
inline float load_voxel(const std::byte* base, std::size_t i) {
  T v;
  std::memcpy(&v, base + i * sizeof(T), sizeof(T));
  return float(v);
}

// Clamps to [0, hi]; NaN goes to 0 so that no NaN ever becomes an index.
inline float clamp_coord(float v, float hi) {
  return v > 0.0f ? (v < hi ? v : hi) : 0.0f;
}

template <class T>
inline float trilinear(const std::byte* brick, glm::ivec3 padded, glm::vec3 pos) {
  // Clamp to the outermost voxel centres (clamp-to-edge), then interpolate the 2x2x2 cell.
  const float cx = clamp_coord(pos.x - 0.5f, float(padded.x - 1));
  const float cy = clamp_coord(pos.y - 0.5f, float(padded.y - 1));
  const float cz = clamp_coord(pos.z - 0.5f, float(padded.z - 1));
  const int x0 = std::min(int(cx), std::max(padded.x - 2, 0));
  const int y0 = std::min(int(cy), std::max(padded.y - 2, 0));
  const int z0 = std::min(int(cz), std::max(padded.z - 2, 0));
  const std::size_t dx = x0 + 1 < padded.x ? 1u : 0u;
  const std::size_t dy = y0 + 1 < padded.y ? std::size_t(padded.x) : 0u;
  const std::size_t dz = z0 + 1 < padded.z ? std::size_t(padded.x) * std::size_t(padded.y) : 0u;
  const float fx = cx - float(x0), fy = cy - float(y0), fz = cz - float(z0);
  const std::size_t i =
      (std::size_t(z0) * std::size_t(padded.y) + std::size_t(y0)) * std::size_t(padded.x) +
      std::size_t(x0);
  const float v000 = load_voxel<T>(brick, i), v100 = load_voxel<T>(brick, i + dx);
  const float v010 = load_voxel<T>(brick, i + dy), v110 = load_voxel<T>(brick, i + dy + dx);
  const float v001 = load_voxel<T>(brick, i + dz), v101 = load_voxel<T>(brick, i + dz + dx);
  const float v011 = load_voxel<T>(brick, i + dz + dy);
  const float v111 = load_voxel<T>(brick, i + dz + dy + dx);
  const float c00 = v000 + fx * (v100 - v000);
  const float c10 = v010 + fx * (v110 - v010);
  const float c01 = v001 + fx * (v101 - v001);
  const float c11 = v011 + fx * (v111 - v011);
  const float c0 = c00 + fy * (c10 - c00);
  const float c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

}  // namespace resoct::cpu::detail

// The kernel's accessors (kernel/traverse.glsl.h) over the context above.
namespace resoct::kernel {

inline uint resoct_read_node(uint index) {
  return cpu::detail::g_ctx.nodes[index];
}
inline uint resoct_read_page(uint index) {
  return cpu::detail::g_ctx.pages[index];
}
inline uint resoct_read_page_table_offset(uint table) {
  return cpu::detail::g_ctx.page_offsets[table];
}
inline ResoctSlotInfo resoct_read_slot(uint i) {
  return cpu::detail::g_ctx.slots[i];
}
inline ResoctLevelInfo resoct_read_level(uint l) {
  return cpu::detail::g_ctx.levels[l];
}
inline ResoctDepthInfo resoct_read_depth(uint d) {
  return cpu::detail::g_ctx.depths[d];
}
inline vec4 resoct_read_tf(uint slot, uint index) {
  return cpu::detail::g_ctx.tf[std::size_t(slot) * 1024u + index];
}
inline float resoct_read_level_size_log2(uint level) {
  return cpu::detail::g_ctx.levels[level].size_log2;
}
inline float resoct_sample_cache(uint cache_slot, vec3 pos) {
  const auto& c = cpu::detail::g_ctx;
  const std::byte* brick = c.cache + std::size_t(cache_slot) * c.slot_voxels * voxel_size(c.type);
  switch (c.type) {
    case VoxelType::u8: return cpu::detail::trilinear<std::uint8_t>(brick, c.padded, pos);
    case VoxelType::u16: return cpu::detail::trilinear<std::uint16_t>(brick, c.padded, pos);
    case VoxelType::f32: return cpu::detail::trilinear<float>(brick, c.padded, pos);
  }
  return 0.0f;
}
inline void resoct_report_request(uint device_key) {
  cpu::detail::g_ctx.brick_requests->insert(device_key);
}
inline void resoct_report_node_request(uint node) {
  cpu::detail::g_ctx.node_requests->insert(node);
}
inline void resoct_mark_used(uint cache_slot) {
  std::atomic<std::uint64_t>& w = cpu::detail::g_ctx.used[cache_slot >> 6u];
  const std::uint64_t bit = std::uint64_t(1) << (cache_slot & 63u);
  // Read first: almost every call finds the bit set, and a read shares the cache line.
  if ((w.load(std::memory_order_relaxed) & bit) == 0) w.fetch_or(bit, std::memory_order_relaxed);
}

}  // namespace resoct::kernel

#include "resoct/kernel/traverse.glsl.h"

namespace resoct::cpu {

namespace {

constexpr std::uint32_t kTile = 16;

// Sums of the per-ray statistics of one frame.
struct RayTotals {
  std::uint64_t samples = 0, nodes = 0, accesses = 0, iterations = 0, caps = 0, requests = 0;
  std::uint64_t gradients = 0, shadow_rays = 0;
  double skipped = 0.0, marched = 0.0;
};

// All tiles of one frame with the kernel specialized for the effect mask EFFECTS: the mask is
// chosen once per frame (render()), so no sample ever branches on it at run time.
template <std::uint32_t EFFECTS>
RayTotals render_tiles(const kernel::ResoctFrame& frame, glm::vec4* pixels, int threads) {
  const std::uint32_t tiles_x = (frame.width + kTile - 1) / kTile;
  const std::uint32_t tiles_y = (frame.height + kTile - 1) / kTile;
  const std::int64_t tile_count = std::int64_t(tiles_x) * tiles_y;
  std::uint64_t samples = 0, nodes = 0, accesses = 0, iterations = 0, caps = 0, requests = 0;
  std::uint64_t gradients = 0, shadow_rays = 0;
  double skipped = 0.0, marched = 0.0;
  // Row-major tile order with dynamic scheduling: neighbouring tiles (coherent rays) run close
  // in time, and uneven tiles (empty vs. dense) balance.
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)                         \
    reduction(+ : samples, nodes, accesses, iterations, caps, requests, skipped, marched, \
                  gradients, shadow_rays)
  for (std::int64_t tile = 0; tile < tile_count; ++tile) {
    const std::uint32_t tx = std::uint32_t(tile % tiles_x) * kTile;
    const std::uint32_t ty = std::uint32_t(tile / tiles_x) * kTile;
    const std::uint32_t x1 = std::min(tx + kTile, frame.width);
    const std::uint32_t y1 = std::min(ty + kTile, frame.height);
    for (std::uint32_t y = ty; y < y1; ++y) {
      for (std::uint32_t x = tx; x < x1; ++x) {
        kernel::ResoctRayStats st{};
        const glm::vec4 p = kernel::resoct_render_pixel_fx<EFFECTS>(frame, x, y, st);
        // The image holds straight alpha (docs/rendering.md "Compositing").
        pixels[std::size_t(y) * frame.width + x] =
            p.a > 0.0f ? glm::vec4(glm::vec3(p) / p.a, p.a) : glm::vec4(0.0f);
        samples += st.samples;
        nodes += st.nodes;
        accesses += st.brick_accesses;
        iterations += st.iterations;
        caps += st.cap_hits;
        requests += st.requests;
        skipped += double(st.skipped);
        marched += double(st.marched);
        if constexpr (EFFECTS != 0u) {
          gradients += st.gradient_evals;
          shadow_rays += st.shadow_rays;
        }
      }
    }
  }
  return {samples,  nodes,     accesses,    iterations, caps,
          requests, gradients, shadow_rays, skipped,    marched};
}

using TileRenderer = RayTotals (*)(const kernel::ResoctFrame&, glm::vec4*, int);

template <std::uint32_t... Masks>
constexpr std::array<TileRenderer, sizeof...(Masks)> make_renderers(
    std::integer_sequence<std::uint32_t, Masks...>) {
  return {&render_tiles<Masks>...};
}

// One instantiation per effect mask (kernel/effects.glsl.h), built at compile time.
constexpr auto kRenderers =
    make_renderers(std::make_integer_sequence<std::uint32_t, kernel::RESOCT_EFFECT_MASKS>());

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
  if (config.node_words > (std::uint64_t(1) << 32)) {
    throw invalid_parameter("config", "node_words exceeds 2^32");
  }
  configured_ = false;
  config_ = config;
  voxel_bytes_ = vb;
  slot_voxels_ = slot_voxels;
  resize_zeroed(cache_, std::size_t(config.cache_slots) * slot_voxels * vb, "brick cache");
  resize_zeroed(pages_, config.page_entries, "page table");
  resize_zeroed(page_offsets_, std::size_t(config.page_tables) + 1u, "page table offsets");
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
  if (u.pages_full) {
    if (u.all_pages.size() != pages_.size()) {
      throw invalid_parameter("update", "full page table of " + std::to_string(u.all_pages.size()) +
                                            " entries, expected " + std::to_string(pages_.size()));
    }
    if (u.page_table_offsets.size() != page_offsets_.size()) {
      throw invalid_parameter("update", "page_table_offsets has the wrong size");
    }
    for (std::uint32_t o : u.page_table_offsets) {
      if (o > pages_.size()) throw invalid_parameter("update", "page table offset out of range");
    }
    std::copy(u.all_pages.begin(), u.all_pages.end(), pages_.begin());
    std::copy(u.page_table_offsets.begin(), u.page_table_offsets.end(), page_offsets_.begin());
  }
  for (const PageDelta& d : u.page_deltas) {
    if (d.index >= pages_.size()) throw invalid_parameter("update", "page delta out of range");
    pages_[d.index] = d.value;
  }
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
  std::lock_guard lock(detail::g_render_mutex);

  detail::KernelContext& c = detail::g_ctx;
  c.nodes = nodes_.data();
  c.pages = pages_.data();
  c.page_offsets = page_offsets_.data();
  c.slots = tables.slots.data();
  c.levels = tables.levels.data();
  c.depths = tables.depths.data();
  c.tf = tables.tf_luts.data();
  c.cache = cache_.data();
  c.slot_voxels = slot_voxels_;
  c.type = config_.voxel_type;
  c.padded = glm::ivec3(config_.padded_brick);
  c.brick_requests = brick_requests_.get();
  c.node_requests = node_requests_.get();
  c.used = used_bits_.get();

  if (result.image.width() != frame.width || result.image.height() != frame.height) {
    result.image = Image(frame.width, frame.height);
  }
  glm::vec4* pixels = result.image.pixels().data();
  const int threads = threads_ > 0 ? threads_ : omp_get_max_threads();
  const RayTotals r = kRenderers[frame.effects & kernel::RESOCT_EFFECT_ANY](frame, pixels, threads);

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

  const std::uint32_t level_count = frame.level_count;
  RequestBatch bricks = brick_requests_->drain([level_count](std::uint32_t key) {
    return kernel::resoct_request_key_table(key) % level_count;
  });
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
