// The CPU backend's segment loop in packets of four samples (src/backend_cpu/segment_packets.hpp)
// against the single-source loop it replaces (kernel/segment_samples.glsl.h, which the Vulkan
// backend runs): for random sources, rays, transfer functions, step levels (full steps from a
// level's corrected LUT, or none), steps, ends and iteration caps,
// both must return bit-identical results: saturation, t, the accumulated colour and every
// statistic, for each compiled copy of the packet loop (baseline and, on x86-64 CPUs that have
// it, AVX2). A difference of one ulp anywhere would make images depend on the backend's loop.
// The same for the loop of segments with several value channels
// (src/backend_cpu/segment_packets_multi.hpp) against the march's per-sample pass
// (kernel::resoct_segment_samples_multi).
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "kernel_access.hpp"

namespace resoct::cpu::detail {
// This executable's own copy of the backend's per-thread context pointer (the library's is
// hidden); both loops below read the brick and the transfer function through it.
__thread const KernelContext* t_ctx = nullptr;
}  // namespace resoct::cpu::detail

namespace {

namespace k = resoct::kernel;
using resoct::VoxelType;
using resoct::cpu::detail::BrickGeometry;
using resoct::cpu::detail::KernelContext;

constexpr glm::ivec3 kPadded{10, 9, 7};

using PacketLoop = bool (*)(const k::ResoctFrame&, const k::ResoctSource&, float, std::uint32_t,
                            float, float, float, float, float, std::uint32_t&, float&, glm::vec4&,
                            k::ResoctRayStats&);

constexpr std::uint32_t kLevels = 3;  // step levels of the fixture's corrected LUTs

// The baseline copy always, the AVX2 copy where the CPU has it and the build made it.
std::vector<PacketLoop> packet_loops() {
  std::vector<PacketLoop> loops{&resoct::cpu::detail::segment_samples_packets_baseline};
#ifdef RESOCT_PACKETS_AVX2
  if (resoct::cpu::detail::segment_packets_avx2()) {
    loops.push_back(&resoct::cpu::detail::segment_samples_packets_avx2);
  }
#endif
  return loops;
}  // not cubic: strides and clamps differ per axis

struct Fixture {
  std::vector<std::byte> cache;      // two slots
  std::vector<glm::vec4> tf;         // two transfer-function slots
  std::vector<glm::vec4> step_luts;  // two slots of kLevels corrected, premultiplied LUTs
  KernelContext ctx;
};

template <class T>
Fixture make_fixture(std::mt19937& rng, VoxelType type) {
  Fixture fx;
  const std::size_t voxels = std::size_t(kPadded.x) * kPadded.y * kPadded.z;
  fx.cache.resize(2 * voxels * sizeof(T) + resoct::cpu::detail::kCacheReadSlack);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::size_t i = 0; i < 2 * voxels; ++i) {
    T v;
    if constexpr (std::is_same_v<T, float>) {
      v = u(rng) * 300.0f - 20.0f;
    } else {
      v = T(rng() % (std::size_t(std::numeric_limits<T>::max()) + 1u));
    }
    std::memcpy(fx.cache.data() + i * sizeof(T), &v, sizeof(T));
  }
  // Transfer functions with every opacity regime of the correction: zero, tiny (series), large
  // (libm), exactly one.
  fx.tf.resize(2 * k::RESOCT_TF_LUT_SIZE);
  for (glm::vec4& e : fx.tf) {
    const float r = u(rng);
    float a = r < 0.2f ? 0.0f : (r < 0.6f ? u(rng) * 0.05f : (r < 0.95f ? u(rng) : 1.0f));
    e = glm::vec4(u(rng), u(rng), u(rng), a);
  }
  // Corrected, premultiplied entries (kernel/step_lut.glsl.h) in the same regimes.
  fx.step_luts.resize(2 * kLevels * k::RESOCT_TF_LUT_SIZE);
  for (glm::vec4& e : fx.step_luts) {
    const float r = u(rng);
    float a = r < 0.2f ? 0.0f : (r < 0.6f ? u(rng) * 0.05f : (r < 0.95f ? u(rng) : 1.0f));
    e = glm::vec4(u(rng) * a, u(rng) * a, u(rng) * a, a);
  }
  fx.ctx.step_luts = fx.step_luts.data();
  fx.ctx.cache = fx.cache.data();
  fx.ctx.slot_voxels = voxels;
  fx.ctx.type = type;
  fx.ctx.geometry = BrickGeometry(kPadded);
  fx.ctx.brick_bytes = voxels * sizeof(T);
  fx.ctx.tf = fx.tf.data();
  return fx;
}

struct Outcome {
  bool saturated;
  float t;
  std::uint32_t j;  // grid step of t
  glm::vec4 acc;
  k::ResoctRayStats stats;
};

void expect_identical(const Outcome& a, const Outcome& b, int c) {
  ASSERT_EQ(a.saturated, b.saturated) << "case " << c;
  ASSERT_EQ(std::bit_cast<std::uint32_t>(a.t), std::bit_cast<std::uint32_t>(b.t)) << "case " << c;
  ASSERT_EQ(a.j, b.j) << "case " << c;
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(std::bit_cast<std::uint32_t>(a.acc[i]), std::bit_cast<std::uint32_t>(b.acc[i]))
        << "case " << c << " component " << i;
  }
  ASSERT_EQ(a.stats.samples, b.stats.samples) << "case " << c;
  ASSERT_EQ(a.stats.brick_accesses, b.stats.brick_accesses) << "case " << c;
  ASSERT_EQ(a.stats.iterations, b.stats.iterations) << "case " << c;
  ASSERT_EQ(std::bit_cast<std::uint32_t>(a.stats.marched),
            std::bit_cast<std::uint32_t>(b.stats.marched))
      << "case " << c;
}

// A random frame for one case: reference step, termination (sometimes never), iteration cap and
// the ray's step level (sometimes none).
struct CaseFrame {
  k::ResoctFrame f{};
  std::uint32_t step_level = 0;
};
CaseFrame random_frame(std::mt19937& rng, std::uniform_real_distribution<float>& u) {
  CaseFrame c;
  c.f.ref_step = 0.002f + u(rng) * 0.01f;
  c.f.ert_opacity = u(rng) < 0.2f ? 2.0f : 0.9f + u(rng) * 0.1f;
  c.f.max_iterations = 40u + std::uint32_t(rng() % 200u);
  c.f.step_level_count = kLevels;
  c.step_level = u(rng) < 0.25f ? k::RESOCT_STEP_LEVEL_NONE : std::uint32_t(rng() % kLevels);
  return c;
}

// A random segment of a step grid and the loop state at its first sample; `valid` is false when
// no sample of it lies before its end and its next decision.
struct CaseSegment {
  float dt = 0, t_grid = 0, t_exit = 0, seg_next = 0, seg = 0, tm = 0;
  Outcome start{};
  bool valid = false;
};
CaseSegment random_segment(std::mt19937& rng, std::uniform_real_distribution<float>& u,
                           const k::ResoctFrame& f) {
  CaseSegment c;
  c.dt = 0.001f + u(rng) * 0.01f;
  // The segment starts at step j0 of a grid (kernel::resoct_grid_t).
  c.t_grid = u(rng) * 0.5f;
  // Some grids far along the ray with steps near or below an ulp of t, where resoct_grid_t's
  // guard decides and the eight-lane copy schedules lane by lane.
  if (u(rng) < 0.05f) {
    c.t_grid = 3000.0f + u(rng);
    c.dt = 1e-4f * (0.5f + 3.0f * u(rng));
  }
  const std::uint32_t j0 = std::uint32_t(rng() % 50u);
  const float t0 = k::resoct_grid_t(c.t_grid, j0, c.dt, -1.0f);
  c.t_exit = t0 + c.dt * (0.5f + u(rng) * 60.0f);
  c.seg_next = u(rng) < 0.5f ? c.t_exit + 1.0f : t0 + c.dt * (1.0f + u(rng) * 40.0f);
  c.seg = k::resoct_segment_length(t0, c.dt, c.t_exit);
  c.tm = t0 + 0.5f * c.seg;
  if (!(c.t_exit - t0 > k::RESOCT_SEGMENT_EPS * c.dt) || !(c.tm < c.seg_next)) return c;
  c.start.t = t0;
  c.start.j = j0;
  const float a0 = u(rng) < 0.5f ? 0.0f : u(rng) * 0.85f;
  c.start.acc = glm::vec4(u(rng) * a0, u(rng) * a0, u(rng) * a0, a0);
  c.start.stats.samples = std::uint32_t(rng() % 100u);
  c.start.stats.brick_accesses = std::uint32_t(rng() % 100u);
  c.start.stats.iterations = f.max_iterations - 1u - std::uint32_t(rng() % 40u);
  c.start.stats.marched = u(rng);
  c.valid = true;
  return c;
}

// Runs `cases` random segments through both loops; returns how many ended by saturation, so
// that the caller can check the cases cover both ends.
template <class T>
int compare_loops(VoxelType type, std::uint32_t seed, int cases) {
  std::mt19937 rng(seed);
  Fixture fx = make_fixture<T>(rng, type);
  resoct::cpu::detail::t_ctx = &fx.ctx;
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int saturated = 0;
  int on_grid = 0;
  for (int c = 0; c < cases; ++c) {
    const CaseFrame cf = random_frame(rng, u);
    const k::ResoctFrame& f = cf.f;
    const std::uint32_t step_level = cf.step_level;

    k::ResoctSource src = k::resoct_source_of(k::RESOCT_CH_VALUE, u(rng) * 1.4f - 0.2f);
    if (u(rng) < 0.05f) src.value = std::numeric_limits<float>::quiet_NaN();
    src.tf_slot = std::uint32_t(rng() % 2u);
    if (u(rng) < 0.85f) {
      src.cache_slot = std::uint32_t(rng() % 2u);
      const float hi = std::is_same_v<T, float> ? 250.0f : float(std::numeric_limits<T>::max());
      src.range_lo = u(rng) * 0.2f * hi;
      src.inv_range_width = 1.0f / (hi * (0.5f + u(rng)));
      // Rays through, into and out of the padded brick (clamps on every side).
      src.ray_base = glm::vec3(u(rng) * 14.0f - 2.0f, u(rng) * 13.0f - 2.0f, u(rng) * 11.0f - 2.0f);
      src.ray_dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f)) *
                    (20.0f + u(rng) * 200.0f);
    }
    const CaseSegment cs = random_segment(rng, u, f);
    if (!cs.valid) continue;
    const float dt = cs.dt, t_grid = cs.t_grid, t_exit = cs.t_exit, seg_next = cs.seg_next;
    const float seg = cs.seg, tm = cs.tm;
    const Outcome& start = cs.start;

    Outcome scalar = start;
    scalar.saturated =
        k::resoct_segment_samples(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                                  scalar.j, scalar.t, scalar.acc, scalar.stats);
    // Every compiled copy of the packet loop this CPU can run (the backend picks one).
    for (auto* loop : packet_loops()) {
      Outcome packets = start;
      packets.saturated = loop(f, src, dt, step_level, t_exit, seg_next, seg, tm, t_grid, packets.j,
                               packets.t, packets.acc, packets.stats);
      expect_identical(scalar, packets, c);
    }
    // The grid index follows t: t is step j of the grid (or the end of the ray's progress).
    if (scalar.t == k::resoct_grid_t(t_grid, scalar.j, dt, -1.0f)) ++on_grid;
    if (::testing::Test::HasFatalFailure()) break;
    if (scalar.saturated) ++saturated;
  }
  resoct::cpu::detail::t_ctx = nullptr;
  EXPECT_GT(on_grid, cases / 2);
  return saturated;
}

using MultiLoop = bool (*)(const k::ResoctFrame&, const k::ResoctSource*, std::uint32_t,
                           std::uint32_t, float, std::uint32_t, float, float, float, float, float,
                           std::uint32_t&, float&, glm::vec4&, k::ResoctRayStats&);

// The multi-channel loop's copies, as packet_loops().
std::vector<MultiLoop> multi_loops() {
  std::vector<MultiLoop> loops{&resoct::cpu::detail::segment_samples_multi_baseline};
#ifdef RESOCT_PACKETS_AVX2
  if (resoct::cpu::detail::segment_packets_avx2()) {
    loops.push_back(&resoct::cpu::detail::segment_samples_multi_avx2);
  }
#endif
  return loops;
}

// Segments in which 2..6 of up to 8 channels yield values (mapped bricks of both cache slots,
// constants, NaN constants), mixed in channel order: the packet copies against the march's
// per-sample pass as kernel::resoct_segment_samples_multi spells it out, bit for bit.
template <class T>
int compare_multi_loops(VoxelType type, std::uint32_t seed, int cases) {
  std::mt19937 rng(seed);
  Fixture fx = make_fixture<T>(rng, type);
  resoct::cpu::detail::t_ctx = &fx.ctx;
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int saturated = 0;
  int ran = 0;
  for (int c = 0; c < cases; ++c) {
    const CaseFrame cf = random_frame(rng, u);
    const k::ResoctFrame& f = cf.f;
    const std::uint32_t step_level = cf.step_level;

    const std::uint32_t n = 2u + std::uint32_t(rng() % 7u);
    k::ResoctSource src[k::RESOCT_MAX_SLOTS];
    std::uint32_t values = 0;
    const glm::vec3 dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
    for (std::uint32_t ch = 0; ch < n; ++ch) {
      src[ch] = k::resoct_source_of(k::RESOCT_CH_NONE, 0.0f);
      if (u(rng) < 0.3f) continue;  // a channel without values in this segment
      values |= 1u << ch;
      src[ch] = k::resoct_source_of(k::RESOCT_CH_VALUE, u(rng) * 1.4f - 0.2f);
      if (u(rng) < 0.05f) src[ch].value = std::numeric_limits<float>::quiet_NaN();
      src[ch].tf_slot = std::uint32_t(rng() % 2u);
      if (u(rng) < 0.8f) {
        src[ch].cache_slot = std::uint32_t(rng() % 2u);
        const float hi = std::is_same_v<T, float> ? 250.0f : float(std::numeric_limits<T>::max());
        src[ch].range_lo = u(rng) * 0.2f * hi;
        src[ch].inv_range_width = 1.0f / (hi * (0.5f + u(rng)));
        // Channels at different levels: the same ray, other scales and bases.
        src[ch].ray_base =
            glm::vec3(u(rng) * 14.0f - 2.0f, u(rng) * 13.0f - 2.0f, u(rng) * 11.0f - 2.0f);
        src[ch].ray_dir = dir * (20.0f + u(rng) * 200.0f);
      }
    }
    if ((values & (values - 1u)) == 0u) continue;  // fewer than two value channels
    const CaseSegment cs = random_segment(rng, u, f);
    if (!cs.valid) continue;
    const float dt = cs.dt, t_grid = cs.t_grid, t_exit = cs.t_exit, seg_next = cs.seg_next;
    const float seg = cs.seg, tm = cs.tm;
    const Outcome& start = cs.start;

    Outcome scalar = start;
    scalar.saturated =
        k::resoct_segment_samples_multi(f, src, values, n, dt, step_level, t_exit, seg_next, seg,
                                        tm, t_grid, scalar.j, scalar.t, scalar.acc, scalar.stats);
    for (auto* loop : multi_loops()) {
      Outcome packets = start;
      packets.saturated = loop(f, src, values, n, dt, step_level, t_exit, seg_next, seg, tm, t_grid,
                               packets.j, packets.t, packets.acc, packets.stats);
      expect_identical(scalar, packets, c);
    }
    if (::testing::Test::HasFatalFailure()) break;
    ++ran;
    if (scalar.saturated) ++saturated;
  }
  resoct::cpu::detail::t_ctx = nullptr;
  EXPECT_GT(ran, cases / 2);
  return saturated;
}

TEST(CpuSegmentPackets, U8BitIdenticalToTheSingleSourceLoop) {
  const int saturated = compare_loops<std::uint8_t>(VoxelType::u8, 11u, 20000);
  EXPECT_GT(saturated, 1000);
  EXPECT_LT(saturated, 19000);
}

TEST(CpuSegmentPackets, U16BitIdenticalToTheSingleSourceLoop) {
  const int saturated = compare_loops<std::uint16_t>(VoxelType::u16, 12u, 20000);
  EXPECT_GT(saturated, 1000);
  EXPECT_LT(saturated, 19000);
}

TEST(CpuSegmentPackets, F32BitIdenticalToTheSingleSourceLoop) {
  const int saturated = compare_loops<float>(VoxelType::f32, 13u, 20000);
  EXPECT_GT(saturated, 1000);
  EXPECT_LT(saturated, 19000);
}

}  // namespace

namespace {

TEST(CpuSegmentPackets, MultiChannelU8BitIdenticalToThePerSamplePass) {
  const int saturated = compare_multi_loops<std::uint8_t>(VoxelType::u8, 21u, 10000);
  EXPECT_GT(saturated, 500);
  EXPECT_LT(saturated, 9500);
}

TEST(CpuSegmentPackets, MultiChannelU16BitIdenticalToThePerSamplePass) {
  const int saturated = compare_multi_loops<std::uint16_t>(VoxelType::u16, 22u, 10000);
  EXPECT_GT(saturated, 500);
  EXPECT_LT(saturated, 9500);
}

TEST(CpuSegmentPackets, MultiChannelF32BitIdenticalToThePerSamplePass) {
  const int saturated = compare_multi_loops<float>(VoxelType::f32, 23u, 10000);
  EXPECT_GT(saturated, 500);
  EXPECT_LT(saturated, 9500);
}

}  // namespace
