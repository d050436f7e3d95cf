#pragma once
// Internal to resoct::cpu: the kernel's accessors over the rendering backend's context (one per
// render() call, reached through a thread-local pointer that each render thread sets) and the
// tile loop of one frame, specialized per effect mask.
// The mask-0 (plain) instantiation and the effect instantiations live in separate translation
// units (render_plain.cpp, render_effects.cpp) so that the compiler's unit-wide inlining budget
// spent on sixteen kernel copies cannot change how the plain kernel is optimized. The same
// split holds with pre-integration (render_preint.cpp, render_effects_preint.cpp), which also
// keeps each unit's compile time and memory those of sixteen copies.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <omp.h>

#include "resoct/engine/request_set.hpp"
#include "resoct/volume/voxel_type.hpp"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/kernel/frame.glsl.h"

namespace resoct::cpu::detail {

// Bytes the cache pool holds after its last brick: the AVX2 segment loop reads a pair of u8
// voxels as one 32-bit word (segment_packets_avx2.hpp), up to two bytes past the pair.
constexpr std::size_t kCacheReadSlack = 64;

// The padded brick's shape as the trilinear lookup uses it, computed once per render.
struct BrickGeometry {
  glm::vec3 hi{0.0f};                  // padded - 1: the last voxel centre (minus 0.5) per axis
  glm::ivec3 last_cell{0};             // max(padded - 2, 0): the last cell with a +1 neighbour
  std::size_t dx = 0, dy = 0, dz = 0;  // strides to the +1 neighbour (0 on a one-voxel axis)
  std::size_t row = 0, slice = 0;      // padded.x, padded.x * padded.y

  explicit BrickGeometry(glm::ivec3 padded = glm::ivec3(1))
      : hi(glm::vec3(padded - 1)),
        last_cell(glm::max(padded - 2, glm::ivec3(0))),
        dx(padded.x > 1 ? 1u : 0u),
        dy(padded.y > 1 ? std::size_t(padded.x) : 0u),
        dz(padded.z > 1 ? std::size_t(padded.x) * std::size_t(padded.y) : 0u),
        row(std::size_t(padded.x)),
        slice(std::size_t(padded.x) * std::size_t(padded.y)) {}
};

// Everything the kernel's accessors read during one render(), built by CpuBackend::render on its
// stack, so that backends in one process render at the same time.
struct KernelContext {
  const std::uint32_t* nodes = nullptr;
  const std::uint32_t* pages = nullptr;  // the page pool
  const std::uint32_t* directory = nullptr;
  const std::uint32_t* directory_offsets = nullptr;
  const kernel::ResoctSlotInfo* slots = nullptr;
  const kernel::ResoctLevelInfo* levels = nullptr;
  const kernel::ResoctDepthInfo* depths = nullptr;
  const glm::vec4* tf = nullptr;
  const glm::vec4* preint = nullptr;                // pre-integration tables (empty frame: unused)
  const glm::vec4* step_luts = nullptr;             // corrected, premultiplied LUTs per step level
  const std::uint32_t* visible_subtrees = nullptr;  // one word per node; null: all zero
  const kernel::ResoctFxFrame* fx = nullptr;
  const std::byte* cache = nullptr;
  std::size_t slot_voxels = 0;
  VoxelType type = VoxelType::u8;
  BrickGeometry geometry;
  std::size_t brick_bytes = 0;  // slot_voxels * voxel size
  RequestSet* brick_requests = nullptr;
  RequestSet* node_requests = nullptr;
  std::atomic<std::uint64_t>* used = nullptr;
};

// The context of the render this thread works for. `__thread` (no dynamic initialization, so no
// TLS wrapper call) with the initial-exec model: an access is one %fs-relative load, not a
// __tls_get_addr call as the default model of a shared library would make it.
extern __thread const KernelContext* t_ctx
    __attribute__((visibility("hidden"), tls_model("initial-exec")));

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

// The trilinear interpolation of the 2x2x2 cell whose lowest voxel is at index i.
template <class T>
[[gnu::always_inline]] inline float interpolate_cell(const std::byte* brick, const BrickGeometry& g,
                                                     std::size_t i, float fx, float fy, float fz) {
  const std::size_t dx = g.dx, dy = g.dy, dz = g.dz;
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

// Always inlined into the kernel's sampling: left to the growth heuristics, GCC moved it out of
// the march once the kernel unit grew (slices and lens), +2 % instructions per frame (callgrind).
template <class T>
[[gnu::always_inline]] inline float trilinear(const std::byte* brick, const BrickGeometry& g,
                                              glm::vec3 pos) {
  // Clamp to the outermost voxel centres (clamp-to-edge), then interpolate the 2x2x2 cell.
  const float cx = clamp_coord(pos.x - 0.5f, g.hi.x);
  const float cy = clamp_coord(pos.y - 0.5f, g.hi.y);
  const float cz = clamp_coord(pos.z - 0.5f, g.hi.z);
  const int x0 = std::min(int(cx), g.last_cell.x);
  const int y0 = std::min(int(cy), g.last_cell.y);
  const int z0 = std::min(int(cz), g.last_cell.z);
  const std::size_t i = std::size_t(z0) * g.slice + std::size_t(y0) * g.row + std::size_t(x0);
  return interpolate_cell<T>(brick, g, i, cx - float(x0), cy - float(y0), cz - float(z0));
}

// The six gradient taps of a sample (kernel/gradient.glsl.h, RESOCT_SAMPLE_CACHE_TAPS): the
// trilinear values at pos ± one voxel per axis (minus only when `central`). Where every tap's
// cell lies inside the padded brick, the taps are the neighbouring cells with the sample's own
// fractions: one clamp, floor and fraction for all six (and the compiler may merge the loads the
// cells share); elsewhere each tap is its own lookup, clamped like any sample.
template <class T>
[[gnu::always_inline]] inline void trilinear_taps(const std::byte* brick, const BrickGeometry& g,
                                                  glm::vec3 pos, bool central, glm::vec3& plus,
                                                  glm::vec3& minus) {
  const float cx = pos.x - 0.5f, cy = pos.y - 0.5f, cz = pos.z - 0.5f;
  const float lo = central ? 1.0f : 0.0f;
  if (cx >= lo && cy >= lo && cz >= lo && cx < float(g.last_cell.x) && cy < float(g.last_cell.y) &&
      cz < float(g.last_cell.z)) {
    const int x0 = int(cx), y0 = int(cy), z0 = int(cz);
    const float fx = cx - float(x0), fy = cy - float(y0), fz = cz - float(z0);
    const std::size_t i = std::size_t(z0) * g.slice + std::size_t(y0) * g.row + std::size_t(x0);
    const std::size_t dx = g.dx, dy = g.dy, dz = g.dz;
    auto cell = [&](std::size_t j) { return interpolate_cell<T>(brick, g, j, fx, fy, fz); };
    plus = glm::vec3(cell(i + dx), cell(i + dy), cell(i + dz));
    minus = central ? glm::vec3(cell(i - dx), cell(i - dy), cell(i - dz)) : glm::vec3(0.0f);
    return;
  }
  for (int a = 0; a < 3; ++a) {
    glm::vec3 q = pos;
    q[a] = pos[a] + 1.0f;
    plus[a] = trilinear<T>(brick, g, q);
    q[a] = pos[a] - 1.0f;
    minus[a] = central ? trilinear<T>(brick, g, q) : 0.0f;
  }
}

}  // namespace resoct::cpu::detail

// The kernel's accessors (kernel/traverse.glsl.h) over the context above. Records are returned
// by reference: the kernel reads a few fields of each, and a by-value copy of a whole record per
// read was measurable in the descent (callgrind).
namespace resoct::kernel {

inline uint resoct_read_node(uint index) {
  return cpu::detail::t_ctx->nodes[index];
}
inline uint resoct_read_page(uint index) {
  return cpu::detail::t_ctx->pages[index];
}
inline uint resoct_read_directory(uint index) {
  return cpu::detail::t_ctx->directory[index];
}
inline uint resoct_read_directory_offset(uint table) {
  return cpu::detail::t_ctx->directory_offsets[table];
}
inline const ResoctSlotInfo& resoct_read_slot(uint i) {
  return cpu::detail::t_ctx->slots[i];
}
inline const ResoctLevelInfo& resoct_read_level(uint l) {
  return cpu::detail::t_ctx->levels[l];
}
inline const ResoctDepthInfo& resoct_read_depth(uint d) {
  return cpu::detail::t_ctx->depths[d];
}
inline vec4 resoct_read_tf(uint slot, uint index) {
  return cpu::detail::t_ctx->tf[std::size_t(slot) * 1024u + index];
}
inline vec4 resoct_read_preint(uint slot, uint index) {
  return cpu::detail::t_ctx->preint[std::size_t(slot) * 2048u + index];
}
inline vec4 resoct_read_step_lut(uint index) {
  return cpu::detail::t_ctx->step_luts[index];
}
inline uint resoct_read_visible_subtrees(uint node) {
  const std::uint32_t* bits = cpu::detail::t_ctx->visible_subtrees;
  return bits != nullptr ? bits[node] : 0u;
}
inline ResoctFxFrame resoct_read_fx_frame() {
  return *cpu::detail::t_ctx->fx;
}
inline float resoct_read_level_size_log2(uint level) {
  return cpu::detail::t_ctx->levels[level].size_log2;
}
inline float resoct_sample_cache(uint cache_slot, vec3 pos) {
  const auto& c = *cpu::detail::t_ctx;
  const std::byte* brick = c.cache + std::size_t(cache_slot) * c.brick_bytes;
  switch (c.type) {
    case VoxelType::u8: return cpu::detail::trilinear<std::uint8_t>(brick, c.geometry, pos);
    case VoxelType::u16: return cpu::detail::trilinear<std::uint16_t>(brick, c.geometry, pos);
    case VoxelType::f32: return cpu::detail::trilinear<float>(brick, c.geometry, pos);
  }
  return 0.0f;
}
inline void resoct_sample_cache_taps_cpu(uint cache_slot, vec3 pos, bool central, vec3& plus,
                                         vec3& minus) {
  const auto& c = *cpu::detail::t_ctx;
  const std::byte* brick = c.cache + std::size_t(cache_slot) * c.brick_bytes;
  switch (c.type) {
    case VoxelType::u8:
      return cpu::detail::trilinear_taps<std::uint8_t>(brick, c.geometry, pos, central, plus,
                                                       minus);
    case VoxelType::u16:
      return cpu::detail::trilinear_taps<std::uint16_t>(brick, c.geometry, pos, central, plus,
                                                        minus);
    case VoxelType::f32:
      return cpu::detail::trilinear_taps<float>(brick, c.geometry, pos, central, plus, minus);
  }
}
inline void resoct_report_request(uint device_key) {
  cpu::detail::t_ctx->brick_requests->insert(device_key);
}
inline void resoct_report_node_request(uint node) {
  cpu::detail::t_ctx->node_requests->insert(node);
}
inline void resoct_mark_used(uint cache_slot) {
  std::atomic<std::uint64_t>& w = cpu::detail::t_ctx->used[cache_slot >> 6u];
  const std::uint64_t bit = std::uint64_t(1) << (cache_slot & 63u);
  // Read first: almost every call finds the bit set, and a read shares the cache line.
  if ((w.load(std::memory_order_relaxed) & bit) == 0) w.fetch_or(bit, std::memory_order_relaxed);
}

}  // namespace resoct::kernel

// The march's segment loops as packets of four or eight samples (same arithmetic): one value
// channel, and several.
#include "segment_packets_avx2.hpp"
#include "segment_packets_multi.hpp"
#define RESOCT_SEGMENT_SAMPLES ::resoct::cpu::detail::segment_samples_packets
#define RESOCT_SEGMENT_SAMPLES_MULTI ::resoct::cpu::detail::segment_samples_multi_packets
#define RESOCT_SAMPLE_CACHE_TAPS ::resoct::kernel::resoct_sample_cache_taps_cpu
#include "resoct/kernel/traverse.glsl.h"

namespace resoct::cpu::detail {

constexpr std::uint32_t kTile = 16;

// Sums of the per-ray statistics of one frame.
struct RayTotals {
  std::uint64_t samples = 0, nodes = 0, accesses = 0, iterations = 0, caps = 0, requests = 0;
  std::uint64_t gradients = 0, shadow_rays = 0;
  double skipped = 0.0, marched = 0.0;
};

// The plain (mask-0) kernel with every kernel helper inlined into it. Left to GCC's growth
// heuristics, the inlining of the page-table/octree/residency channel helpers and the camera
// ray into the march changed with every feature added to the kernel unit (effects, slices,
// lens), each time costing instructions per sample on the path of scenes that use none of
// them; flattening makes the plain path's code independent of those features. Only mask 0 is
// flattened: the effect kernels' shadow and gradient marches would multiply in size.
// Pre-integration alone (RESOCT_EFFECT_PREINT) is a plain path too and is flattened likewise.
template <std::uint32_t EFFECTS>
[[gnu::flatten]] inline glm::vec4 resoct_render_pixel_plain(const kernel::ResoctFrame& frame,
                                                            std::uint32_t x, std::uint32_t y,
                                                            kernel::ResoctRayStats& st) {
  return kernel::resoct_render_pixel_fx<EFFECTS>(frame, x, y, st);
}

// All tiles of one frame with the kernel specialized for the effect mask EFFECTS: the mask is
// chosen once per frame (render()), so no sample ever branches on it at run time.
template <std::uint32_t EFFECTS>
RayTotals render_tiles(const KernelContext& ctx, const kernel::ResoctFrame& frame,
                       glm::vec4* pixels, int threads) {
  const std::uint32_t tiles_x = (frame.width + kTile - 1) / kTile;
  const std::uint32_t tiles_y = (frame.height + kTile - 1) / kTile;
  const std::int64_t tile_count = std::int64_t(tiles_x) * tiles_y;
  std::uint64_t samples = 0, nodes = 0, accesses = 0, iterations = 0, caps = 0, requests = 0;
  std::uint64_t gradients = 0, shadow_rays = 0;
  double skipped = 0.0, marched = 0.0;
  // Row-major tile order with dynamic scheduling: neighbouring tiles (coherent rays) run close
  // in time, and uneven tiles (empty vs. dense) balance.
#pragma omp parallel num_threads(threads)                                                    \
    reduction(+ : samples, nodes, accesses, iterations, caps, requests, skipped, marched, \
                  gradients, shadow_rays)
  {
    t_ctx = &ctx;
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t tile = 0; tile < tile_count; ++tile) {
      const std::uint32_t tx = std::uint32_t(tile % tiles_x) * kTile;
      const std::uint32_t ty = std::uint32_t(tile / tiles_x) * kTile;
      const std::uint32_t x1 = std::min(tx + kTile, frame.width);
      const std::uint32_t y1 = std::min(ty + kTile, frame.height);
      for (std::uint32_t y = ty; y < y1; ++y) {
        for (std::uint32_t x = tx; x < x1; ++x) {
          kernel::ResoctRayStats st{};
          glm::vec4 p;
          if constexpr ((EFFECTS & kernel::RESOCT_EFFECT_ANY) == 0u) {
            p = resoct_render_pixel_plain<EFFECTS>(frame, x, y, st);
          } else {
            p = kernel::resoct_render_pixel_fx<EFFECTS>(frame, x, y, st);
          }
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
          if constexpr ((EFFECTS & (kernel::RESOCT_EFFECT_MASKS - 1u)) != 0u) {
            gradients += st.gradient_evals;
            shadow_rays += st.shadow_rays;
          }
        }
      }
    }
    t_ctx = nullptr;
  }
  return {samples,  nodes,     accesses,    iterations, caps,
          requests, gradients, shadow_rays, skipped,    marched};
}

/// The plain kernel (render_plain.cpp).
RayTotals render_plain(const KernelContext& ctx, const kernel::ResoctFrame& frame,
                       glm::vec4* pixels, int threads);
/// The plain kernel with pre-integration, mask RESOCT_EFFECT_PREINT (render_preint.cpp).
RayTotals render_preint(const KernelContext& ctx, const kernel::ResoctFrame& frame,
                        glm::vec4* pixels, int threads);
/// The kernel specialized for `mask` (1 .. 15; render_effects.cpp).
RayTotals render_effects(std::uint32_t mask, const KernelContext& ctx,
                         const kernel::ResoctFrame& frame, glm::vec4* pixels, int threads);
/// The kernel specialized for `mask` (17 .. 31: effects with pre-integration;
/// render_effects_preint.cpp).
RayTotals render_effects_preint(std::uint32_t mask, const KernelContext& ctx,
                                const kernel::ResoctFrame& frame, glm::vec4* pixels, int threads);

}  // namespace resoct::cpu::detail
