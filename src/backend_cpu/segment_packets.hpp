#pragma once
// Internal to resoct::cpu: the kernel's single-source segment loop
// (kernel/segment_samples.glsl.h) run as packets of four samples.
//
// Between two decisions of the march one channel's source is fixed and the sample positions are
// affine in t, so four consecutive samples are independent until they are composited. A packet
// computes their positions, trilinear lookups, transfer-function indices and opacity corrections
// four lanes at a time (GCC/Clang vector extensions: SSE2 on the x86-64 baseline, NEON on
// AArch64), then composites them in order with the early-termination test after each. Every
// lane performs exactly the scalar loop's IEEE operations in the scalar loop's order (no fused
// multiply-add, no reassociation), so images, sample counts and statistics are bit-identical to
// the loop it replaces; tests/cpu/test_cpu_segment_packets.cpp checks that against the
// single-source loop.
//
// On x86-64 an AVX2 copy of eight lanes (segment_packets_avx2.hpp) is chosen once per process
// when the CPU has it (__builtin_cpu_supports); it performs the same IEEE operations per lane in
// the same order, and the test checks both copies against the single-source loop. Sanitizer
// builds keep this baseline only.
//
// Included (through segment_packets_avx2.hpp) by kernel_access.hpp after the kernel accessors,
// before kernel/traverse.glsl.h, whose march calls it through RESOCT_SEGMENT_SAMPLES.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "resoct/kernel/channel_sample.glsl.h"
#include "resoct/kernel/composite.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/step_lut.glsl.h"
#include "resoct/kernel/tf.glsl.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__)
#if defined(__has_feature)
#if !__has_feature(address_sanitizer) && !__has_feature(thread_sanitizer)
#define RESOCT_PACKETS_AVX2 1
#endif
#else
#define RESOCT_PACKETS_AVX2 1
#endif
#endif

namespace resoct::cpu::detail {

using v4f = float __attribute__((vector_size(16)));
using v4i = std::int32_t __attribute__((vector_size(16)));

inline v4f splat(float x) {
  return v4f{x, x, x, x};
}
inline v4i splat(std::int32_t x) {
  return v4i{x, x, x, x};
}
// Lane-wise `mask ? a : b` for comparison masks (all bits set or clear), as bit operations: the
// vector `?:` is not available in every compiler the project builds with.
inline v4f select(v4i mask, v4f a, v4f b) {
  return v4f((mask & v4i(a)) | (~mask & v4i(b)));
}
inline v4i select(v4i mask, v4i a, v4i b) {
  return (mask & a) | (~mask & b);
}

// clamp_coord (kernel_access.hpp) per lane: [0, hi], NaN to 0.
inline v4f clamp_coord4(v4f v, float hi) {
  const v4f h = splat(hi);
  return select(v > splat(0.0f), select(v < h, v, h), splat(0.0f));
}

// trilinear<T> (kernel_access.hpp) at four positions: the same clamps, cell and lerps per lane.
template <class T>
[[gnu::always_inline]] inline v4f trilinear4(const std::byte* brick, const BrickGeometry& g, v4f px,
                                             v4f py, v4f pz) {
  const v4f cx = clamp_coord4(px - splat(0.5f), g.hi.x);
  const v4f cy = clamp_coord4(py - splat(0.5f), g.hi.y);
  const v4f cz = clamp_coord4(pz - splat(0.5f), g.hi.z);
  // std::min(int(c), last_cell): truncation (c >= 0), then (last < x) ? last : x.
  v4i x0 = __builtin_convertvector(cx, v4i);
  v4i y0 = __builtin_convertvector(cy, v4i);
  v4i z0 = __builtin_convertvector(cz, v4i);
  x0 = select(splat(g.last_cell.x) < x0, splat(g.last_cell.x), x0);
  y0 = select(splat(g.last_cell.y) < y0, splat(g.last_cell.y), y0);
  z0 = select(splat(g.last_cell.z) < z0, splat(g.last_cell.z), z0);
  const v4f fx = cx - __builtin_convertvector(x0, v4f);
  const v4f fy = cy - __builtin_convertvector(y0, v4f);
  const v4f fz = cz - __builtin_convertvector(z0, v4f);
  v4f v000, v100, v010, v110, v001, v101, v011, v111;
  const std::size_t dx = g.dx, dy = g.dy, dz = g.dz;
  for (int l = 0; l < 4; ++l) {
    const std::size_t i =
        std::size_t(z0[l]) * g.slice + std::size_t(y0[l]) * g.row + std::size_t(x0[l]);
    v000[l] = load_voxel<T>(brick, i);
    v100[l] = load_voxel<T>(brick, i + dx);
    v010[l] = load_voxel<T>(brick, i + dy);
    v110[l] = load_voxel<T>(brick, i + dy + dx);
    v001[l] = load_voxel<T>(brick, i + dz);
    v101[l] = load_voxel<T>(brick, i + dz + dx);
    v011[l] = load_voxel<T>(brick, i + dz + dy);
    v111[l] = load_voxel<T>(brick, i + dz + dy + dx);
  }
  const v4f c00 = v000 + fx * (v100 - v000);
  const v4f c10 = v010 + fx * (v110 - v010);
  const v4f c01 = v001 + fx * (v101 - v001);
  const v4f c11 = v011 + fx * (v111 - v011);
  const v4f c0 = c00 + fy * (c10 - c00);
  const v4f c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

inline v4f load4(const glm::vec4& v) {
  v4f r;
  std::memcpy(&r, &v, sizeof(r));
  return r;
}

// The loop's running state, read from the march's arguments once and written back once.
struct PacketLoopState {
  v4f a;            // accumulated colour, premultiplied
  float t_now;      // start of the pending sample
  std::uint32_t j;  // grid step of t_now (kernel::resoct_grid_t)
  std::uint32_t samples, accesses, iterations;
  float marched;
  float tm, seg;  // the pending sample's midpoint and length
  bool saturated = false;
};

inline PacketLoopState packet_loop_begin(float seg, float tm, std::uint32_t grid_j, float t,
                                         const glm::vec4& acc,
                                         const kernel::ResoctRayStats& stats) {
  return {load4(acc),    t,  grid_j, stats.samples, stats.brick_accesses, stats.iterations,
          stats.marched, tm, seg};
}

inline bool packet_loop_end(const PacketLoopState& s, std::uint32_t& grid_j, float& t,
                            glm::vec4& acc, kernel::ResoctRayStats& stats) {
  t = s.t_now;
  grid_j = s.j;
  std::memcpy(&acc, &s.a, sizeof(acc));
  stats.samples = s.samples;
  stats.brick_accesses = s.accesses;
  stats.iterations = s.iterations;
  stats.marched = s.marched;
  return s.saturated;
}

// A packet of up to N samples, scheduled exactly as the scalar loop's control would run them if
// none saturated: lane k starts at lane_t[k], is sampled at lane_tm[k] and is lane_seg[k] long;
// after lane m - 1 the loop either ends (`ends`, at t_after) or goes on with the pending sample
// (next_tm, next_seg) that starts at t_after.
template <int N>
struct PacketSchedule {
  float lane_tm[N], lane_seg[N], lane_t[N];
  int m = 1;
  bool ends = false;
  float t_after = 0.0f, next_seg = 0.0f, next_tm = 0.0f;
};

// The scalar loop's control, one lane at a time from lane `sc.m` on (lanes before it are set).
template <int N>
[[gnu::always_inline]] inline void schedule_lanes(const kernel::ResoctFrame& f, float dt,
                                                  float t_exit, float seg_next, float t_grid,
                                                  const PacketLoopState& s, PacketSchedule<N>& sc) {
  using namespace kernel;
  const float eps_dt = RESOCT_SEGMENT_EPS * dt;
  for (;;) {
    sc.t_after = resoct_grid_t(t_grid, s.j + std::uint32_t(sc.m), dt, sc.lane_t[sc.m - 1]);
    // The scalar loop counts one iteration per sample after the first.
    if (!(t_exit - sc.t_after > eps_dt) ||
        s.iterations + std::uint32_t(sc.m - 1) >= f.max_iterations) {
      sc.ends = true;
      return;
    }
    sc.next_seg = resoct_segment_length(sc.t_after, dt, t_exit);
    sc.next_tm = sc.t_after + 0.5f * sc.next_seg;
    if (!(sc.next_tm < seg_next)) {
      sc.ends = true;
      return;
    }
    if (sc.m == N) return;
    sc.lane_tm[sc.m] = sc.next_tm;
    sc.lane_seg[sc.m] = sc.next_seg;
    sc.lane_t[sc.m] = sc.t_after;
    ++sc.m;
  }
}

// The next packet of the loop in state `s`: lane 0 is the pending sample, the others follow the
// scalar loop's control (schedule_lanes); unused lanes repeat lane 0, so that their reads stay
// inside the bricks.
[[gnu::always_inline]] inline void next_packet4(const kernel::ResoctFrame& f, float dt,
                                                float t_exit, float seg_next, float t_grid,
                                                const PacketLoopState& s, PacketSchedule<4>& sc) {
  sc.lane_tm[0] = s.tm;
  sc.lane_seg[0] = s.seg;
  sc.lane_t[0] = s.t_now;
  schedule_lanes(f, dt, t_exit, seg_next, t_grid, s, sc);
  for (int l = sc.m; l < 4; ++l) {
    sc.lane_tm[l] = sc.lane_tm[0];
    sc.lane_seg[l] = sc.lane_seg[0];
  }
}

// A packet's normalized values of one source at the lanes' midpoints `tmv`
// (resoct_source_sample_t per lane): the constant, or the trilinear samples of its mapped brick.
[[gnu::always_inline]] inline v4f source_values4(const KernelContext& ctx,
                                                 const kernel::ResoctSource& src,
                                                 const std::byte* brick, v4f tmv) {
  if (brick == nullptr) return splat(src.value);
  const v4f px = splat(src.ray_base.x) + tmv * splat(src.ray_dir.x);
  const v4f py = splat(src.ray_base.y) + tmv * splat(src.ray_dir.y);
  const v4f pz = splat(src.ray_base.z) + tmv * splat(src.ray_dir.z);
  v4f raw;
  switch (ctx.type) {
    case VoxelType::u8: raw = trilinear4<std::uint8_t>(brick, ctx.geometry, px, py, pz); break;
    case VoxelType::u16: raw = trilinear4<std::uint16_t>(brick, ctx.geometry, px, py, pz); break;
    default: raw = trilinear4<float>(brick, ctx.geometry, px, py, pz); break;
  }
  return (raw - splat(src.range_lo)) * splat(src.inv_range_width);
}

// resoct_tf_lookup's clamp (GLM's min(max(v, 0), 1)), LUT index and fraction per lane, and the
// lanes whose value is NaN.
struct TfIndex4 {
  v4i nan, i0;
  v4f fr;
};
[[gnu::always_inline]] inline TfIndex4 tf_index4(v4f value) {
  TfIndex4 r;
  r.nan = value != value;
  v4f x = select(value < splat(0.0f), splat(0.0f), value);
  x = select(splat(1.0f) < x, splat(1.0f), x) * splat(float(kernel::RESOCT_TF_LUT_SIZE - 1u));
  r.i0 = __builtin_convertvector(x, v4i);
  const std::int32_t last = std::int32_t(kernel::RESOCT_TF_LUT_SIZE - 2u);
  r.i0 = select(splat(last) < r.i0, splat(last), r.i0);
  r.fr = x - __builtin_convertvector(r.i0, v4f);
  return r;
}

// A full step's premultiplied colour from a step level's corrected LUT
// (resoct_step_lut_lookup, 0 where alpha is 0): entries i and i + 1 weighted by 1 - fr and fr,
// i = 0 for a NaN value.
[[gnu::always_inline]] inline v4f level_lut_sample(const glm::vec4* level_lut, std::size_t i,
                                                   float one_minus_fr, float fr, bool nan) {
  const v4f p = load4(level_lut[i]) * splat(one_minus_fr) + load4(level_lut[i + 1u]) * splat(fr);
  return nan || !(p[3] > 0.0f) ? splat(0.0f) : p;
}

// Lane `l`'s premultiplied sample (resoct_mix_result of this one channel) from its normalized
// value, LUT index i0 and fraction fr: a full step of a ray with a step level from the level's
// LUT (resoct_step_lut_lookup, 0 where alpha is 0), any other step corrected per sample with the
// kernel's own functions.
[[gnu::always_inline]] inline v4f lane_sample(const kernel::ResoctFrame& f,
                                              const kernel::ResoctSource& src,
                                              const glm::vec4* level_lut, float dt, float seg,
                                              float value, bool nan, std::int32_t i0, float fr) {
  using namespace kernel;
  if (level_lut != nullptr && seg == dt) {
    return level_lut_sample(level_lut, nan ? 0u : std::size_t(i0), 1.0f - fr, fr, nan);
  }
  const vec4 rgba = resoct_tf_lookup(src.tf_slot, value);
  const float al = resoct_correct_opacity(rgba.a, resoct_step_ratio(seg, f.ref_step));
  return al > 0.0f ? load4(resoct_premultiply(vec3(rgba.r, rgba.g, rgba.b), al)) : splat(0.0f);
}

// Composites the packet's samples in order with the early-termination test after each, as the
// scalar loop does, and moves the state past them. Returns true when the loop is over
// (saturated, or the schedule ends).
// Each sample counts `accesses` brick accesses (its mapped channels).
template <int N>
[[gnu::always_inline]] inline bool composite_lanes(const kernel::ResoctFrame& f,
                                                   std::uint32_t accesses, const v4f* pm,
                                                   const PacketSchedule<N>& sc,
                                                   PacketLoopState& s) {
  // Only the colour and the marched length (float sums) follow the lanes one by one; the integer
  // counters, which the scalar loop bumps per sample, are added once per packet: the same totals.
  for (int l = 0; l < sc.m; ++l) {
    s.a = s.a + splat(1.0f - s.a[3]) * pm[l];
    if (s.a[3] >= f.ert_opacity) {
      const std::uint32_t done = std::uint32_t(l) + 1u;
      s.samples += done;
      s.accesses += done * accesses;
      s.iterations += done - 1u;  // one per sample after the first
      s.saturated = true;
      s.t_now = sc.lane_t[l];
      s.j = s.j + std::uint32_t(l);
      return true;
    }
    s.marched = s.marched + sc.lane_seg[l];
  }
  const std::uint32_t done = std::uint32_t(sc.m);
  s.samples += done;
  s.accesses += done * accesses;
  s.iterations += done - 1u;
  s.t_now = sc.t_after;
  s.j = s.j + done;
  if (sc.ends) return true;
  ++s.iterations;
  s.tm = sc.next_tm;
  s.seg = sc.next_seg;
  return false;
}

// The step level's corrected, premultiplied LUT of the source's slot (kernel/step_lut.glsl.h),
// or null without a level.
inline const glm::vec4* level_lut_of(const KernelContext& ctx, const kernel::ResoctFrame& f,
                                     const kernel::ResoctSource& src, std::uint32_t step_level) {
  if (step_level == kernel::RESOCT_STEP_LEVEL_NONE) return nullptr;
  return ctx.step_luts +
         (std::size_t(src.tf_slot) * f.step_level_count + step_level) * kernel::RESOCT_TF_LUT_SIZE;
}

// The loop, with kernel::resoct_segment_samples' contract; inlined into each compiled copy.
[[gnu::always_inline]] inline bool segment_samples_packets_body(
    const kernel::ResoctFrame& f, const kernel::ResoctSource& src, float dt,
    std::uint32_t step_level, float t_exit, float seg_next, float seg, float tm, float t_grid,
    std::uint32_t& grid_j, float& t, glm::vec4& acc, kernel::ResoctRayStats& stats) {
  using namespace kernel;
  const KernelContext& ctx = *t_ctx;
  const bool mapped = src.cache_slot != RESOCT_SOURCE_NO_SLOT;
  const std::byte* brick =
      mapped ? ctx.cache + std::size_t(src.cache_slot) * ctx.brick_bytes : nullptr;
  const glm::vec4* level_lut = level_lut_of(ctx, f, src, step_level);
  PacketLoopState s = packet_loop_begin(seg, tm, grid_j, t, acc, stats);
  for (;;) {
    PacketSchedule<4> sc;
    next_packet4(f, dt, t_exit, seg_next, t_grid, s, sc);

    const v4f tmv{sc.lane_tm[0], sc.lane_tm[1], sc.lane_tm[2], sc.lane_tm[3]};
    const v4f value = source_values4(ctx, src, brick, tmv);
    const TfIndex4 ix = tf_index4(value);
    v4f pm[4];
    for (int l = 0; l < sc.m; ++l) {
      pm[l] = lane_sample(f, src, level_lut, dt, sc.lane_seg[l], value[l], ix.nan[l] != 0, ix.i0[l],
                          ix.fr[l]);
    }
    if (composite_lanes(f, mapped ? 1u : 0u, pm, sc, s)) break;
  }
  return packet_loop_end(s, grid_j, t, acc, stats);
}

// The compiled copies, kept out of the march (noinline) like the loop they replace.
[[gnu::noinline]] inline bool segment_samples_packets_baseline(
    const kernel::ResoctFrame& f, const kernel::ResoctSource& src, float dt,
    std::uint32_t step_level, float t_exit, float seg_next, float seg, float tm, float t_grid,
    std::uint32_t& grid_j, float& t, glm::vec4& acc, kernel::ResoctRayStats& stats) {
  return segment_samples_packets_body(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                                      grid_j, t, acc, stats);
}
/// Whether this process runs the AVX2 copy of the loop.
inline bool segment_packets_avx2() {
#ifdef RESOCT_PACKETS_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  return avx2;
#else
  return false;
#endif
}

}  // namespace resoct::cpu::detail
