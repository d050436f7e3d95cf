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
// On x86-64 the loop is compiled twice: for the baseline (SSE2) and for AVX2 (three-operand
// forms, blends, 32-bit lane multiplies), chosen once per process from the CPU
// (__builtin_cpu_supports). The AVX2 copy performs the same IEEE operations in the same order
// (the target does not include FMA, so nothing is fused), and the test checks both copies against
// the single-source loop. Sanitizer builds keep the baseline only.
//
// Included by kernel_access.hpp after the kernel accessors, before kernel/traverse.glsl.h, whose
// march calls it through RESOCT_SEGMENT_SAMPLES.
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

// kernel::resoct_correct_opacity per lane. The series of both factors run on all lanes; a lane
// outside a series' range calls the scalar kernel function (its libm branch).
inline v4f correct_opacity4(v4f alpha, v4f ratio) {
  using namespace kernel;
  const v4f one = splat(1.0f);
  v4f la = -alpha *
           (one + alpha * (splat(0.5f) +
                           alpha * (splat(0.33333333f) +
                                    alpha * (splat(0.25f) +
                                             alpha * (splat(0.2f) + alpha * splat(0.16666667f))))));
  const v4i positive = (alpha > splat(0.0f)) & (ratio > splat(0.0f));
  const v4i valid = positive & ~(alpha >= one);
  const v4i la_libm = valid & ~(alpha < splat(RESOCT_SERIES_LIMIT));
  for (int l = 0; l < 4; ++l) {
    if (la_libm[l] != 0) la[l] = resoct_log_one_minus(alpha[l]);
  }
  const v4f y = ratio * la;
  v4f r =
      -y *
      (one + y * (splat(0.5f) + y * (splat(0.16666667f) +
                                     y * (splat(0.041666668f) +
                                          y * (splat(0.0083333333f) + y * splat(0.0013888889f))))));
  const v4i e_libm = valid & ~(y > splat(-RESOCT_SERIES_LIMIT));
  for (int l = 0; l < 4; ++l) {
    if (e_libm[l] != 0) r[l] = resoct_one_minus_exp(y[l]);
  }
  // glm::clamp(r, 0, 1) = min(max(r, 0), 1) with GLM's (x < y) ? y : x.
  r = select(r < splat(0.0f), splat(0.0f), r);
  r = select(one < r, one, r);
  // Invalid lanes: 1 where the reference alpha is at least 1, else 0.
  return select(valid, r, select(positive & (alpha >= one), one, splat(0.0f)));
}

inline v4f load4(const glm::vec4& v) {
  v4f r;
  std::memcpy(&r, &v, sizeof(r));
  return r;
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
  const glm::vec4* tf = ctx.tf + std::size_t(src.tf_slot) * RESOCT_TF_LUT_SIZE;
  // The step level's corrected, premultiplied LUT (kernel/step_lut.glsl.h), for full steps.
  const bool have_level = step_level != RESOCT_STEP_LEVEL_NONE;
  const glm::vec4* level_lut =
      have_level ? ctx.step_luts + (std::size_t(src.tf_slot) * f.step_level_count + step_level) *
                                       RESOCT_TF_LUT_SIZE
                 : nullptr;
  const float eps_dt = RESOCT_SEGMENT_EPS * dt;

  v4f a = load4(acc);
  float t_now = t;
  std::uint32_t j = grid_j;  // step index of t_now on the grid (kernel::resoct_grid_t)
  std::uint32_t samples = stats.samples;
  std::uint32_t accesses = stats.brick_accesses;
  std::uint32_t iterations = stats.iterations;
  float marched = stats.marched;
  bool saturated = false;
  // The pending sample: midpoint tm, length seg, starting at t_now.
  for (;;) {
    // Schedule up to four samples exactly as the scalar loop's control would run them if none
    // saturated: lane k starts at lane_t[k]; after the last lane the loop either ends (t_end)
    // or goes on with a pending fifth sample (next_*).
    float lane_tm[4], lane_seg[4], lane_t[4];
    int m = 1;
    lane_tm[0] = tm;
    lane_seg[0] = seg;
    lane_t[0] = t_now;
    bool ends = false;
    float t_after = 0.0f, next_seg = 0.0f, next_tm = 0.0f;
    for (;;) {
      t_after = resoct_grid_t(t_grid, j + std::uint32_t(m), dt, lane_t[m - 1]);
      // The scalar loop counts one iteration per sample after the first.
      if (!(t_exit - t_after > eps_dt) || iterations + std::uint32_t(m - 1) >= f.max_iterations) {
        ends = true;
        break;
      }
      next_seg = resoct_segment_length(t_after, dt, t_exit);
      next_tm = t_after + 0.5f * next_seg;
      if (!(next_tm < seg_next)) {
        ends = true;
        break;
      }
      if (m == 4) break;
      lane_tm[m] = next_tm;
      lane_seg[m] = next_seg;
      lane_t[m] = t_after;
      ++m;
    }
    // Unused lanes repeat lane 0, so that their loads stay inside the brick.
    for (int l = m; l < 4; ++l) {
      lane_tm[l] = lane_tm[0];
      lane_seg[l] = lane_seg[0];
    }

    const v4f tmv{lane_tm[0], lane_tm[1], lane_tm[2], lane_tm[3]};
    v4f value = splat(src.value);
    if (mapped) {
      const v4f px = splat(src.ray_base.x) + tmv * splat(src.ray_dir.x);
      const v4f py = splat(src.ray_base.y) + tmv * splat(src.ray_dir.y);
      const v4f pz = splat(src.ray_base.z) + tmv * splat(src.ray_dir.z);
      v4f raw;
      switch (ctx.type) {
        case VoxelType::u8: raw = trilinear4<std::uint8_t>(brick, ctx.geometry, px, py, pz); break;
        case VoxelType::u16:
          raw = trilinear4<std::uint16_t>(brick, ctx.geometry, px, py, pz);
          break;
        default: raw = trilinear4<float>(brick, ctx.geometry, px, py, pz); break;
      }
      value = (raw - splat(src.range_lo)) * splat(src.inv_range_width);
    }
    // resoct_tf_lookup: clamp (GLM's min(max(v, 0), 1)), index, lerp of two entries.
    const v4i nan = value != value;
    v4f x = select(value < splat(0.0f), splat(0.0f), value);
    x = select(splat(1.0f) < x, splat(1.0f), x) * splat(float(RESOCT_TF_LUT_SIZE - 1u));
    v4i i0 = __builtin_convertvector(x, v4i);
    const std::int32_t last = std::int32_t(RESOCT_TF_LUT_SIZE - 2u);
    i0 = select(splat(last) < i0, splat(last), i0);
    const v4f fr = x - __builtin_convertvector(i0, v4f);
    // Each lane's premultiplied sample (resoct_mix_result of this one channel): full steps of a
    // ray with a step level from the level's LUT (resoct_step_lut_lookup, 0 where alpha is 0),
    // the others (the last, shorter step) corrected per sample.
    v4f pm[4];
    bool per_sample = !have_level;
    for (int l = 0; l < m; ++l) per_sample = per_sample || lane_seg[l] != dt;
    if (per_sample) {
      v4f rgba[4];
      v4f alpha;
      for (int l = 0; l < 4; ++l) {
        // glm::mix(a, b, f) = a * (1 - f) + b * f, per component.
        const std::size_t i = nan[l] != 0 ? 0u : std::size_t(i0[l]);
        rgba[l] = load4(tf[i]) * splat(1.0f - fr[l]) + load4(tf[i + 1u]) * splat(fr[l]);
        if (nan[l] != 0) rgba[l] = splat(0.0f);
        alpha[l] = rgba[l][3];
      }
      // kernel::resoct_step_ratio per lane.
      const v4f ratio =
          v4f{lane_seg[0], lane_seg[1], lane_seg[2], lane_seg[3]} * splat(1.0f / f.ref_step);
      const v4f corrected = correct_opacity4(alpha, ratio);
      for (int l = 0; l < 4; ++l) {
        const float al = corrected[l];
        pm[l] = splat(0.0f);
        if (al > 0.0f) {
          pm[l] = rgba[l] * splat(al);
          pm[l][3] = al;
        }
      }
    }
    if (have_level) {
      for (int l = 0; l < m; ++l) {
        if (lane_seg[l] != dt) continue;
        const std::size_t i = nan[l] != 0 ? 0u : std::size_t(i0[l]);
        v4f p = load4(level_lut[i]) * splat(1.0f - fr[l]) + load4(level_lut[i + 1u]) * splat(fr[l]);
        if (nan[l] != 0 || !(p[3] > 0.0f)) p = splat(0.0f);
        pm[l] = p;
      }
    }

    // Composite in order, as the scalar loop does.
    for (int l = 0; l < m; ++l) {
      if (mapped) ++accesses;
      ++samples;
      a = a + splat(1.0f - a[3]) * pm[l];
      if (a[3] >= f.ert_opacity) {
        saturated = true;
        t_now = lane_t[l];
        j = j + std::uint32_t(l);
        break;
      }
      marched = marched + lane_seg[l];
      if (l + 1 < m) ++iterations;
    }
    if (saturated) break;
    t_now = t_after;
    j = j + std::uint32_t(m);
    if (ends) break;
    ++iterations;
    tm = next_tm;
    seg = next_seg;
  }
  t = t_now;
  grid_j = j;
  std::memcpy(&acc, &a, sizeof(acc));
  stats.samples = samples;
  stats.brick_accesses = accesses;
  stats.iterations = iterations;
  stats.marched = marched;
  return saturated;
}

// The compiled copies, kept out of the march (noinline) like the loop they replace.
[[gnu::noinline]] inline bool segment_samples_packets_baseline(
    const kernel::ResoctFrame& f, const kernel::ResoctSource& src, float dt,
    std::uint32_t step_level, float t_exit, float seg_next, float seg, float tm, float t_grid,
    std::uint32_t& grid_j, float& t, glm::vec4& acc, kernel::ResoctRayStats& stats) {
  return segment_samples_packets_body(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                                      grid_j, t, acc, stats);
}
#ifdef RESOCT_PACKETS_AVX2
[[gnu::noinline, gnu::target("avx2")]] inline bool segment_samples_packets_avx2(
    const kernel::ResoctFrame& f, const kernel::ResoctSource& src, float dt,
    std::uint32_t step_level, float t_exit, float seg_next, float seg, float tm, float t_grid,
    std::uint32_t& grid_j, float& t, glm::vec4& acc, kernel::ResoctRayStats& stats) {
  return segment_samples_packets_body(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                                      grid_j, t, acc, stats);
}
#endif

/// Whether this process runs the AVX2 copy of the loop.
inline bool segment_packets_avx2() {
#ifdef RESOCT_PACKETS_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  return avx2;
#else
  return false;
#endif
}

// The march's entry (RESOCT_SEGMENT_SAMPLES): the copy this CPU runs fastest.
inline bool segment_samples_packets(const kernel::ResoctFrame& f, const kernel::ResoctSource& src,
                                    float dt, std::uint32_t step_level, float t_exit,
                                    float seg_next, float seg, float tm, float t_grid,
                                    std::uint32_t& grid_j, float& t, glm::vec4& acc,
                                    kernel::ResoctRayStats& stats) {
#ifdef RESOCT_PACKETS_AVX2
  if (segment_packets_avx2()) {
    return segment_samples_packets_avx2(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                                        grid_j, t, acc, stats);
  }
#endif
  return segment_samples_packets_baseline(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                                          grid_j, t, acc, stats);
}

}  // namespace resoct::cpu::detail
