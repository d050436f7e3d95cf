#pragma once
// Internal to resoct::cpu: segments in which several channels yield values, as packets.
//
// The march's per-sample pass (kernel/traverse.glsl.h) handles a segment with two or more value
// channels one sample per pass of the whole march loop, with each channel's trilinear footprint
// read by scalar code. Between two decisions every channel's source is fixed and the sample
// positions are affine in t, so the samples of a packet are independent until they are mixed and
// composited: this loop reads each channel's footprints for a packet at once (four lanes on the
// x86-64 baseline, eight with AVX2 gathers, the single-channel loop's trilinear4 / trilinear8),
// then per lane mixes the channels in channel order and composites the lanes in order with the
// early-termination test after each. Per lane these are the pass's IEEE operations in the pass's
// order (kernel::resoct_segment_samples_multi spells them out), so images, sample counts and
// statistics are bit-identical to it; tests/cpu/test_cpu_segment_packets.cpp checks both copies
// against it, and the Vulkan oracle tests check the CPU backend against the shaders, which run
// the pass itself.
//
// Included by kernel_access.hpp after segment_packets_avx2.hpp, before kernel/traverse.glsl.h,
// whose march calls it through RESOCT_SEGMENT_SAMPLES_MULTI.
#include <cstddef>
#include <cstdint>

#include "segment_packets_avx2.hpp"

namespace resoct::cpu::detail {

// One value channel of a segment, read once per segment.
struct MultiChannel {
  const kernel::ResoctSource* src;
  const std::byte* brick;      // the mapped brick's voxels; null for a constant
  const glm::vec4* level_lut;  // the step level's corrected LUT; null without a level
};

// The segment's value channels, in channel order; returns their count and the number of them
// that read a brick (brick accesses per sample).
inline std::uint32_t multi_channels(const KernelContext& ctx, const kernel::ResoctFrame& f,
                                    const kernel::ResoctSource* src, std::uint32_t values,
                                    std::uint32_t n, std::uint32_t step_level, MultiChannel* ch,
                                    std::uint32_t& mapped) {
  using namespace kernel;
  std::uint32_t k = 0;
  mapped = 0;
  for (std::uint32_t c = 0; c < n && c < RESOCT_MAX_SLOTS; ++c) {
    if (((values >> c) & 1u) == 0u) continue;
    const ResoctSource& s = src[c];
    const bool m = s.cache_slot != RESOCT_SOURCE_NO_SLOT;
    ch[k++] = {&s, m ? ctx.cache + std::size_t(s.cache_slot) * ctx.brick_bytes : nullptr,
               level_lut_of(ctx, f, s, step_level)};
    if (m) ++mapped;
  }
  return k;
}

// Adds lane l's sample of one channel to the lane's mix: resoct_mix_add_premultiplied of
// resoct_step_lut_lookup for a full step of a ray with a step level (NaN transparent), else
// resoct_mix_add of the corrected transfer-function colour, with the kernel's own functions.
[[gnu::always_inline]] inline void mix_lane(const kernel::ResoctFrame& f, const MultiChannel& ch,
                                            float dt, float seg, float value, bool nan,
                                            std::int32_t i0, float fr, v4f& weighted,
                                            float& combined) {
  using namespace kernel;
  if (ch.level_lut != nullptr && seg == dt) {
    v4f p = splat(0.0f);
    if (!nan) {
      p = load4(ch.level_lut[i0]) * splat(1.0f - fr) + load4(ch.level_lut[i0 + 1]) * splat(fr);
    }
    weighted = weighted + p;
    combined = combined + (1.0f - combined) * p[3];
    return;
  }
  const vec4 rgba = resoct_tf_lookup(ch.src->tf_slot, value);
  const float al = resoct_correct_opacity(rgba.a, resoct_step_ratio(seg, f.ref_step));
  weighted = weighted + v4f{rgba.r * al, rgba.g * al, rgba.b * al, al};
  combined = combined + (1.0f - combined) * al;
}

// resoct_mix_result of one lane's mix, premultiplied.
[[gnu::always_inline]] inline v4f mix_result_lane(v4f weighted, float combined) {
  if (!(weighted[3] > 0.0f)) return splat(0.0f);
  const float q = combined / weighted[3];
  return v4f{weighted[0] * q, weighted[1] * q, weighted[2] * q, combined};
}

// The baseline copy: packets of four.
[[gnu::noinline]] inline bool segment_samples_multi_baseline(
    const kernel::ResoctFrame& f, const kernel::ResoctSource* src, std::uint32_t values,
    std::uint32_t n, float dt, std::uint32_t step_level, float t_exit, float seg_next, float seg,
    float tm, float t_grid, std::uint32_t& grid_j, float& t, glm::vec4& acc,
    kernel::ResoctRayStats& stats) {
  using namespace kernel;
  const KernelContext& ctx = *t_ctx;
  MultiChannel ch[RESOCT_MAX_SLOTS];
  std::uint32_t mapped = 0;
  const std::uint32_t k = multi_channels(ctx, f, src, values, n, step_level, ch, mapped);
  PacketLoopState s = packet_loop_begin(seg, tm, grid_j, t, acc, stats);
  for (;;) {
    PacketSchedule<4> sc;
    next_packet4(f, dt, t_exit, seg_next, t_grid, s, sc);
    const v4f tmv{sc.lane_tm[0], sc.lane_tm[1], sc.lane_tm[2], sc.lane_tm[3]};
    v4f weighted[4];
    float combined[4];
    for (int l = 0; l < 4; ++l) {
      weighted[l] = splat(0.0f);
      combined[l] = 0.0f;
    }
    for (std::uint32_t c = 0; c < k; ++c) {
      const v4f value = source_values4(ctx, *ch[c].src, ch[c].brick, tmv);
      const TfIndex4 ix = tf_index4(value);
      for (int l = 0; l < sc.m; ++l) {
        mix_lane(f, ch[c], dt, sc.lane_seg[l], value[l], ix.nan[l] != 0, ix.i0[l], ix.fr[l],
                 weighted[l], combined[l]);
      }
    }
    v4f pm[4];
    for (int l = 0; l < sc.m; ++l) pm[l] = mix_result_lane(weighted[l], combined[l]);
    if (composite_lanes(f, mapped, pm, sc, s)) break;
  }
  return packet_loop_end(s, grid_j, t, acc, stats);
}

#ifdef RESOCT_PACKETS_AVX2

// The AVX2 copy: packets of eight, footprints of u8 and u16 voxels gathered (trilinear8).
[[gnu::noinline, gnu::target("avx2")]] inline bool segment_samples_multi_avx2(
    const kernel::ResoctFrame& f, const kernel::ResoctSource* src, std::uint32_t values,
    std::uint32_t n, float dt, std::uint32_t step_level, float t_exit, float seg_next, float seg,
    float tm, float t_grid, std::uint32_t& grid_j, float& t, glm::vec4& acc,
    kernel::ResoctRayStats& stats) {
  using namespace kernel;
  const KernelContext& ctx = *t_ctx;
  // Gathers need x + 1 next to x; a one-voxel-wide padded brick takes the four-lane copy.
  if (ctx.geometry.dx != 1u) {
    return segment_samples_multi_baseline(f, src, values, n, dt, step_level, t_exit, seg_next, seg,
                                          tm, t_grid, grid_j, t, acc, stats);
  }
  MultiChannel ch[RESOCT_MAX_SLOTS];
  std::uint32_t mapped = 0;
  const std::uint32_t k = multi_channels(ctx, f, src, values, n, step_level, ch, mapped);
  PacketLoopState s = packet_loop_begin(seg, tm, grid_j, t, acc, stats);
  for (;;) {
    Packet8 p;
    next_packet8(f, dt, t_exit, seg_next, t_grid, s, p);
    const PacketSchedule<8>& sc = p.sc;
    const v8f tmv = p.tm;
    v4f weighted[8];
    float combined[8];
    for (int l = 0; l < 8; ++l) {
      weighted[l] = splat(0.0f);
      combined[l] = 0.0f;
    }
    for (std::uint32_t c = 0; c < k; ++c) {
      const v8f value = source_values8(ctx, *ch[c].src, ch[c].brick, tmv);
      const TfIndex8 ix = tf_index8(value);
      for (int l = 0; l < sc.m; ++l) {
        mix_lane(f, ch[c], dt, sc.lane_seg[l], value[l], ix.nan[l] != 0, ix.i0[l], ix.fr[l],
                 weighted[l], combined[l]);
      }
    }
    v4f pm[8];
    for (int l = 0; l < sc.m; ++l) pm[l] = mix_result_lane(weighted[l], combined[l]);
    if (composite_lanes(f, mapped, pm, sc, s)) break;
  }
  return packet_loop_end(s, grid_j, t, acc, stats);
}

#endif  // RESOCT_PACKETS_AVX2

// The march's entry (RESOCT_SEGMENT_SAMPLES_MULTI): the copy this CPU runs fastest.
inline bool segment_samples_multi_packets(const kernel::ResoctFrame& f,
                                          const kernel::ResoctSource* src, std::uint32_t values,
                                          std::uint32_t n, float dt, std::uint32_t step_level,
                                          float t_exit, float seg_next, float seg, float tm,
                                          float t_grid, std::uint32_t& grid_j, float& t,
                                          glm::vec4& acc, kernel::ResoctRayStats& stats) {
#ifdef RESOCT_PACKETS_AVX2
  if (segment_packets_avx2()) {
    return segment_samples_multi_avx2(f, src, values, n, dt, step_level, t_exit, seg_next, seg, tm,
                                      t_grid, grid_j, t, acc, stats);
  }
#endif
  return segment_samples_multi_baseline(f, src, values, n, dt, step_level, t_exit, seg_next, seg,
                                        tm, t_grid, grid_j, t, acc, stats);
}

}  // namespace resoct::cpu::detail
