#pragma once
// Internal to resoct::cpu: the AVX2 copy of the segment loop (segment_packets.hpp), eight
// samples per packet.
//
// The same contract and, lane by lane, the same IEEE operations in the same order as the
// single-source loop (kernel/segment_samples.glsl.h), so t, colours and statistics are
// bit-identical to it (tests/cpu/test_cpu_segment_packets.cpp); what differs from the four-lane
// baseline copy is how the work is spread:
//   - the schedule of a packet is computed for all eight lanes at once: step k of the grid is
//     t_grid + float(j + k) * dt (resoct_grid_t) wherever those values strictly increase, which
//     is checked, and the scalar schedule runs where they do not (steps below an ulp of t); the
//     lane that ends the packet is the first set bit of the lanes' end conditions, and the lanes'
//     midpoints and lengths stay in vectors;
//   - the eight trilinear footprints of u8 and u16 voxels are read with gathers, two voxels per
//     32-bit word (x and x + 1 are adjacent); f32 voxels with scalar loads (faster than eight
//     gathers); all are interpolated eight lanes wide;
//   - the transfer function's LUT indices and fractions are computed eight lanes wide; a packet
//     of full steps reads its colours from the step level's LUT per lane, other steps correct
//     their opacity per lane, and compositing stays per lane, in order.
// The target does not include FMA, so no multiply-add is contracted. Reading a u8 pair as a
// 32-bit word reads up to two bytes past the pair: the backend's cache pool has
// kCacheReadSlack bytes of slack after its last brick.
#include <immintrin.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "segment_packets.hpp"

namespace resoct::cpu::detail {

#ifdef RESOCT_PACKETS_AVX2

using v8f = float __attribute__((vector_size(32)));
using v8i = std::int32_t __attribute__((vector_size(32)));

[[gnu::target("avx2")]] inline v8f splat8(float x) {
  return v8f{x, x, x, x, x, x, x, x};
}
[[gnu::target("avx2")]] inline v8i splat8(std::int32_t x) {
  return v8i{x, x, x, x, x, x, x, x};
}
[[gnu::target("avx2")]] inline v8f select8(v8i mask, v8f a, v8f b) {
  return v8f((mask & v8i(a)) | (~mask & v8i(b)));
}
[[gnu::target("avx2")]] inline v8i select8(v8i mask, v8i a, v8i b) {
  return (mask & a) | (~mask & b);
}
// clamp_coord (kernel_access.hpp) per lane: [0, hi], NaN to 0.
[[gnu::target("avx2")]] inline v8f clamp_coord8(v8f v, float hi) {
  const v8f h = splat8(hi);
  return select8(v > splat8(0.0f), select8(v < h, v, h), splat8(0.0f));
}
// 32-bit words at byte offsets `off` from `base`.
[[gnu::target("avx2")]] inline v8i gather_words(const std::byte* base, v8i off) {
  return v8i(_mm256_i32gather_epi32(reinterpret_cast<const int*>(base), __m256i(off), 1));
}

// The voxel pairs (x0, x0 + 1) of one row of the eight footprints of u8 or u16 voxels, as
// floats: `off` is the byte offset of voxel x0; one word holds both (dx = 1 voxel).
template <class T>
[[gnu::target("avx2"), gnu::always_inline]] inline void gather_pair(const std::byte* brick, v8i off,
                                                                    v8f& lo, v8f& hi) {
  static_assert(sizeof(T) < 4);
  const v8i w = gather_words(brick, off);
  constexpr std::int32_t mask = sizeof(T) == 1 ? 0xFF : 0xFFFF;
  constexpr int shift = 8 * int(sizeof(T));
  lo = __builtin_convertvector(w & splat8(mask), v8f);
  hi = __builtin_convertvector((w >> shift) & splat8(mask), v8f);
}

// trilinear<T> (kernel_access.hpp) at eight positions: the same clamps, cell and lerps per lane.
// Needs dx == 1 (the padded brick is more than one voxel wide).
template <class T>
[[gnu::target("avx2"), gnu::always_inline]] inline v8f trilinear8(const std::byte* brick,
                                                                  const BrickGeometry& g, v8f px,
                                                                  v8f py, v8f pz) {
  const v8f cx = clamp_coord8(px - splat8(0.5f), g.hi.x);
  const v8f cy = clamp_coord8(py - splat8(0.5f), g.hi.y);
  const v8f cz = clamp_coord8(pz - splat8(0.5f), g.hi.z);
  v8i x0 = __builtin_convertvector(cx, v8i);
  v8i y0 = __builtin_convertvector(cy, v8i);
  v8i z0 = __builtin_convertvector(cz, v8i);
  x0 = select8(splat8(g.last_cell.x) < x0, splat8(g.last_cell.x), x0);
  y0 = select8(splat8(g.last_cell.y) < y0, splat8(g.last_cell.y), y0);
  z0 = select8(splat8(g.last_cell.z) < z0, splat8(g.last_cell.z), z0);
  const v8f fx = cx - __builtin_convertvector(x0, v8f);
  const v8f fy = cy - __builtin_convertvector(y0, v8f);
  const v8f fz = cz - __builtin_convertvector(z0, v8f);
  const std::int32_t size = std::int32_t(sizeof(T));
  const v8i i =
      (z0 * splat8(std::int32_t(g.slice)) + y0 * splat8(std::int32_t(g.row)) + x0) * splat8(size);
  v8f v000, v100, v010, v110, v001, v101, v011, v111;
  if constexpr (sizeof(T) == 4) {
    // f32 would take eight gathers per packet, one per voxel of the footprint; scalar loads,
    // lane by lane, measured 1.4-5 % less CPU time per frame on the sphere (bench/README.md,
    // twelfth pass). The packed types read two voxels per gathered word, where gathers win.
    const std::size_t dy = g.dy * sizeof(T), dz = g.dz * sizeof(T);
    for (int l = 0; l < 8; ++l) {
      const std::size_t o = std::size_t(i[l]);
      v000[l] = load_voxel<float>(brick + o, 0);
      v100[l] = load_voxel<float>(brick + o, 1);
      v010[l] = load_voxel<float>(brick + o + dy, 0);
      v110[l] = load_voxel<float>(brick + o + dy, 1);
      v001[l] = load_voxel<float>(brick + o + dz, 0);
      v101[l] = load_voxel<float>(brick + o + dz, 1);
      v011[l] = load_voxel<float>(brick + o + dz + dy, 0);
      v111[l] = load_voxel<float>(brick + o + dz + dy, 1);
    }
  } else {
    const v8i dy = splat8(std::int32_t(g.dy) * size), dz = splat8(std::int32_t(g.dz) * size);
    gather_pair<T>(brick, i, v000, v100);
    gather_pair<T>(brick, i + dy, v010, v110);
    gather_pair<T>(brick, i + dz, v001, v101);
    gather_pair<T>(brick, i + dz + dy, v011, v111);
  }
  const v8f c00 = v000 + fx * (v100 - v000);
  const v8f c10 = v010 + fx * (v110 - v010);
  const v8f c01 = v001 + fx * (v101 - v001);
  const v8f c11 = v011 + fx * (v111 - v011);
  const v8f c0 = c00 + fy * (c10 - c00);
  const v8f c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

// source_values4 (segment_packets.hpp) for eight lanes.
[[gnu::target("avx2"), gnu::always_inline]] inline v8f source_values8(
    const KernelContext& ctx, const kernel::ResoctSource& src, const std::byte* brick, v8f tmv) {
  if (brick == nullptr) return splat8(src.value);
  const v8f px = splat8(src.ray_base.x) + tmv * splat8(src.ray_dir.x);
  const v8f py = splat8(src.ray_base.y) + tmv * splat8(src.ray_dir.y);
  const v8f pz = splat8(src.ray_base.z) + tmv * splat8(src.ray_dir.z);
  v8f raw;
  switch (ctx.type) {
    case VoxelType::u8: raw = trilinear8<std::uint8_t>(brick, ctx.geometry, px, py, pz); break;
    case VoxelType::u16: raw = trilinear8<std::uint16_t>(brick, ctx.geometry, px, py, pz); break;
    default: raw = trilinear8<float>(brick, ctx.geometry, px, py, pz); break;
  }
  return (raw - splat8(src.range_lo)) * splat8(src.inv_range_width);
}

// tf_index4 (segment_packets.hpp) for eight lanes.
struct TfIndex8 {
  v8i nan, i0;
  v8f fr;
};
[[gnu::target("avx2"), gnu::always_inline]] inline TfIndex8 tf_index8(v8f value) {
  TfIndex8 r;
  r.nan = value != value;
  v8f x = select8(value < splat8(0.0f), splat8(0.0f), value);
  x = select8(splat8(1.0f) < x, splat8(1.0f), x) * splat8(float(kernel::RESOCT_TF_LUT_SIZE - 1u));
  r.i0 = __builtin_convertvector(x, v8i);
  const std::int32_t last = std::int32_t(kernel::RESOCT_TF_LUT_SIZE - 2u);
  r.i0 = select8(splat8(last) < r.i0, splat8(last), r.i0);
  r.fr = x - __builtin_convertvector(r.i0, v8f);
  return r;
}

// Lanes {x, v[0], ..., v[6]}: a vector moved up by one lane, x in lane 0.
[[gnu::target("avx2"), gnu::always_inline]] inline v8f shift_in8(v8f v, float x) {
  return __builtin_shuffle(v, splat8(x), v8i{8, 0, 1, 2, 3, 4, 5, 6});
}
// Bit k set where lane k's comparison mask is set.
[[gnu::target("avx2"), gnu::always_inline]] inline unsigned lane_bits8(v8i mask) {
  return unsigned(_mm256_movemask_ps(__m256(mask)));
}

// An eight-lane packet as vectors: its schedule (PacketSchedule, lanes 0 .. m - 1; its lane_t
// and lane_seg are set, its lane_tm only on the scalar path, so read `tm`), and each lane's
// midpoint and length, unused lanes repeating lane 0 so that their reads stay inside the bricks.
struct Packet8 {
  PacketSchedule<8> sc;
  v8f tm, seg;
};

// The next packet of the loop in state `s` (next_packet4 for eight lanes): lane 0 is the pending
// sample; the scalar loop's control for lanes 1 .. 7 is computed for all lanes at once where the
// grid's steps strictly increase.
[[gnu::target("avx2"), gnu::always_inline]] inline void next_packet8(const kernel::ResoctFrame& f,
                                                                     float dt, float t_exit,
                                                                     float seg_next, float t_grid,
                                                                     const PacketLoopState& s,
                                                                     Packet8& p) {
  using namespace kernel;
  PacketSchedule<8>& sc = p.sc;
  const float eps_dt = RESOCT_SEGMENT_EPS * dt;
  const v8f lane_index{1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f, 8.0f};
  // Steps j + 1 .. j + 8 at once (resoct_grid_t: float(j + k) * dt, then + t_grid; j + 8 is
  // exact in float far beyond any iteration cap). Where they do not strictly increase (steps
  // below an ulp of t), resoct_grid_t's guard decides: the scalar schedule runs.
  const v8f starts = splat8(t_grid) + (splat8(float(s.j)) + lane_index) * splat8(dt);
  const v8f lane_t = shift_in8(starts, s.t_now);
  const bool increasing = lane_bits8(starts > lane_t) == 0xFFu && float(s.j) + 8.0f < 16777216.0f;
  if (increasing) {
    // resoct_segment_length: max(min(dt, t_exit - t), 0) with GLM's min (y < x ? y : x) and
    // max (x < y ? y : x).
    const v8f rest = splat8(t_exit) - starts;
    const v8f segs = select8(rest < splat8(dt), rest, splat8(dt));
    const v8f seg_len = select8(segs < splat8(0.0f), splat8(0.0f), segs);
    const v8f mids = starts + splat8(0.5f) * seg_len;
    // Lane k - 1 of these vectors is the candidate for lane k: the loop ends at the first k whose
    // start leaves less than eps of a step, whose midpoint reaches seg_next, or that hits the
    // iteration cap (the scalar loop's iterations + k - 1 >= max_iterations; iterations never
    // exceeds the cap, the march checks it first).
    unsigned fail = ~lane_bits8((rest > splat8(eps_dt)) & (mids < splat8(seg_next))) & 0xFFu;
    const std::uint32_t room =
        f.max_iterations > s.iterations ? f.max_iterations - s.iterations : 0u;
    if (room < 8u) fail |= (0xFFu << room) & 0xFFu;
    if (fail != 0u) {
      const int k = std::countr_zero(fail) + 1;
      sc.t_after = starts[k - 1];
      sc.ends = true;
      sc.m = k;
    } else {
      sc.t_after = starts[7];
      sc.next_seg = seg_len[7];
      sc.next_tm = mids[7];
      sc.m = 8;
    }
    const v8i used = v8i{0, 1, 2, 3, 4, 5, 6, 7} < splat8(std::int32_t(sc.m));
    p.tm = select8(used, shift_in8(mids, s.tm), splat8(s.tm));
    p.seg = select8(used, shift_in8(seg_len, s.seg), splat8(s.seg));
    std::memcpy(sc.lane_t, &lane_t, sizeof(lane_t));
    std::memcpy(sc.lane_seg, &p.seg, sizeof(p.seg));
  } else {
    sc.lane_tm[0] = s.tm;
    sc.lane_seg[0] = s.seg;
    sc.lane_t[0] = s.t_now;
    schedule_lanes(f, dt, t_exit, seg_next, t_grid, s, sc);
    for (int l = sc.m; l < 8; ++l) {
      sc.lane_tm[l] = sc.lane_tm[0];
      sc.lane_seg[l] = sc.lane_seg[0];
    }
    std::memcpy(&p.tm, sc.lane_tm, sizeof(p.tm));
    std::memcpy(&p.seg, sc.lane_seg, sizeof(p.seg));
  }
}

// The premultiplied samples of a packet whose lanes are all full steps of a ray with a step
// level: level_lut_sample per lane, its index (0 for NaN), fraction and 1 - fraction computed
// eight lanes at a time (the same IEEE operation per lane).
[[gnu::target("avx2"), gnu::always_inline]] inline void level_samples8(const glm::vec4* level_lut,
                                                                       const TfIndex8& ix, int m,
                                                                       v4f* pm) {
  alignas(32) std::int32_t idx[8];
  alignas(32) float fr[8], omf[8];
  alignas(32) std::int32_t nan[8];
  const v8i i0 = select8(ix.nan, splat8(std::int32_t(0)), ix.i0);
  const v8f one_minus = splat8(1.0f) - ix.fr;
  std::memcpy(idx, &i0, sizeof(idx));
  std::memcpy(fr, &ix.fr, sizeof(fr));
  std::memcpy(omf, &one_minus, sizeof(omf));
  std::memcpy(nan, &ix.nan, sizeof(nan));
  for (int l = 0; l < m; ++l) {
    pm[l] = level_lut_sample(level_lut, std::size_t(idx[l]), omf[l], fr[l], nan[l] != 0);
  }
}

// The loop in packets of eight, with kernel::resoct_segment_samples' contract.
[[gnu::noinline, gnu::target("avx2")]] inline bool segment_samples_packets_avx2(
    const kernel::ResoctFrame& f, const kernel::ResoctSource& src, float dt,
    std::uint32_t step_level, float t_exit, float seg_next, float seg, float tm, float t_grid,
    std::uint32_t& grid_j, float& t, glm::vec4& acc, kernel::ResoctRayStats& stats) {
  using namespace kernel;
  const KernelContext& ctx = *t_ctx;
  const bool mapped = src.cache_slot != RESOCT_SOURCE_NO_SLOT;
  // Gathers need x + 1 next to x; a one-voxel-wide padded brick takes the four-lane copy.
  if (mapped && ctx.geometry.dx != 1u) {
    return segment_samples_packets_baseline(f, src, dt, step_level, t_exit, seg_next, seg, tm,
                                            t_grid, grid_j, t, acc, stats);
  }
  const std::byte* brick =
      mapped ? ctx.cache + std::size_t(src.cache_slot) * ctx.brick_bytes : nullptr;
  const glm::vec4* level_lut = level_lut_of(ctx, f, src, step_level);
  PacketLoopState s = packet_loop_begin(seg, tm, grid_j, t, acc, stats);
  for (;;) {
    Packet8 p;
    next_packet8(f, dt, t_exit, seg_next, t_grid, s, p);
    const PacketSchedule<8>& sc = p.sc;

    const v8f value = source_values8(ctx, src, brick, p.tm);
    const TfIndex8 ix = tf_index8(value);
    v4f pm[8];
    // Unused lanes repeat lane 0, so all eight are full steps when the used ones are.
    if (level_lut != nullptr && lane_bits8(p.seg == splat8(dt)) == 0xFFu) {
      level_samples8(level_lut, ix, sc.m, pm);
    } else {
      for (int l = 0; l < sc.m; ++l) {
        pm[l] = lane_sample(f, src, level_lut, dt, sc.lane_seg[l], value[l], ix.nan[l] != 0,
                            ix.i0[l], ix.fr[l]);
      }
    }
    if (composite_lanes(f, mapped ? 1u : 0u, pm, sc, s)) break;
  }
  return packet_loop_end(s, grid_j, t, acc, stats);
}

#endif  // RESOCT_PACKETS_AVX2

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
