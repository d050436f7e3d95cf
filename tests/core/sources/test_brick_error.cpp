// measure_brick_error(): the measured down-sampling error of a coarse brick (the largest difference
// between the level's trilinear reconstruction and the level-0 voxels, at their centres), its
// region-spread bound above the budget, and the page entry's error code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/sources/brick_error.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

BrickLayout bricks8() {
  BrickLayout l;
  l.brick_size = glm::uvec3(8);
  return l;
}

template <class T>
InMemorySource source_of(glm::u64vec3 e, VoxelType t, const std::vector<T>& values) {
  VolumeDesc d;
  d.extent = e;
  d.type = t;
  d.channels = 1;
  return InMemorySource(DenseVolume::from_values(d, values), bricks8());
}

std::vector<std::byte> padded(const BrickSource& s, BrickKey key) {
  std::vector<std::byte> out(s.hierarchy().layout().padded_voxels() * voxel_size(s.volume().type));
  s.read_brick(key, out);
  return out;
}

double error_of(const BrickSource& s, BrickKey key,
                std::uint64_t budget = kBrickErrorMeasuredVoxels) {
  return measure_brick_error(s, key, padded(s, key), budget);
}

// v(x) = (x + 0.5) / 64 along x, constant along y and z.
InMemorySource ramp() {
  const glm::u64vec3 e(64, 16, 16);
  std::vector<float> v(std::size_t(e.x * e.y * e.z));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = float((double(i % e.x) + 0.5) / 64.0);
  return source_of(e, VoxelType::f32, v);
}

TEST(BrickError, CodesAreTheLargestPowerOfTwoBound) {
  EXPECT_EQ(brick_error_code(0.0), 15u);
  EXPECT_EQ(brick_error_code(1e-9), 15u);
  EXPECT_EQ(brick_error_code(1.0), 0u);
  EXPECT_EQ(brick_error_code(7.0), 0u);
  EXPECT_EQ(brick_error_code(std::numeric_limits<double>::quiet_NaN()), 0u);
  EXPECT_EQ(brick_error_code(0.5), 1u);
  EXPECT_EQ(brick_error_code(0.50001), 0u);
  EXPECT_EQ(brick_error_code(0.25), 2u);
  EXPECT_EQ(brick_error_code(0.26), 1u);
  EXPECT_EQ(brick_error_code(std::ldexp(1.0, -14)), 14u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-16.0, 0.0);
  for (int i = 0; i < 10000; ++i) {
    const double e = std::exp2(u(rng));
    const std::uint32_t k = brick_error_code(e);
    ASSERT_LE(e, std::ldexp(1.0, -int(k))) << e;                  // a bound, never an underestimate
    if (k < 15) ASSERT_GT(e, std::ldexp(1.0, -int(k) - 1)) << e;  // and the tightest one
  }
}

TEST(BrickError, LevelZeroAndConstantDataHaveNone) {
  const glm::u64vec3 e(32, 32, 32);
  const InMemorySource s = source_of(e, VoxelType::u8, std::vector<std::uint8_t>(32768, 100));
  const BrickHierarchy& h = s.hierarchy();
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    EXPECT_EQ(error_of(s, BrickKey(l, 0, glm::uvec3(0))), 0.0) << "level " << l;
  }
}

TEST(BrickError, ACheckerboardLosesHalfTheRange) {
  const glm::u64vec3 e(16, 16, 16);
  std::vector<std::uint8_t> v(4096);
  for (std::size_t i = 0; i < v.size(); ++i) {
    v[i] = ((i % 16) + (i / 16 % 16) + (i / 256)) % 2 == 0 ? 0 : 255;
  }
  const InMemorySource s = source_of(e, VoxelType::u8, v);
  // Level 1 averages four 0 and four 255: every coarse voxel is 127 or 128, 128 from one side.
  EXPECT_NEAR(error_of(s, BrickKey(1, 0, glm::uvec3(0))), 128.0 / 255.0, 1e-12);
}

TEST(BrickError, MeasuresTheTrilinearReconstructionAtVoxelCentres) {
  const InMemorySource s = ramp();
  // Inside the volume the box filter and trilinear reconstruction reproduce a linear ramp: only
  // float rounding remains. A half-voxel slip in the positions would give 1/128 here.
  EXPECT_LT(error_of(s, BrickKey(1, 0, {1, 0, 0})), 1e-6);
  // At the volume's face the reconstruction clamps to the first coarse voxel: level 1's first
  // voxel holds 1/64, level 2's 2/64, the first level-0 voxel 0.5/64.
  EXPECT_NEAR(error_of(s, BrickKey(1, 0, {0, 0, 0})), 0.5 / 64.0, 1e-6);
  EXPECT_NEAR(error_of(s, BrickKey(2, 0, {0, 0, 0})), 1.5 / 64.0, 1e-6);
}

// The definition spelt out, independently of the measurement's separable passes: at every
// level-0 voxel centre under the brick, the eight-tap trilinear reconstruction of the padded
// brick (taps of weight zero left out, so a NaN there does not count) against the level-0 voxel
// read from the volume itself; the largest difference over the range's width.
double reference_error(const InMemorySource& s, const std::vector<double>& level0, BrickKey key) {
  const BrickHierarchy& h = s.hierarchy();
  const BrickLayout& layout = h.layout();
  const glm::uvec3 ps = layout.padded_size();
  const std::vector<std::byte> raw = padded(s, key);
  const VoxelType type = s.volume().type;
  const auto coarse = [&](int x, int y, int z) {
    return voxel_value(
        raw.data() +
            (std::size_t(x) + ps.x * (std::size_t(y) + ps.y * std::size_t(z))) * voxel_size(type),
        type);
  };
  const glm::uvec3 f = h.level(key.level()).factor_log2;
  const Box3 core = h.core_box(key.level(), key.brick());
  const Box3 box0 = h.level0_box(key.level(), key.brick());
  const glm::u64vec3 e = s.volume().extent;
  double worst = 0.0;
  for (std::int64_t z = box0.lo.z; z < box0.hi.z; ++z) {
    for (std::int64_t y = box0.lo.y; y < box0.hi.y; ++y) {
      for (std::int64_t x = box0.lo.x; x < box0.hi.x; ++x) {
        const double v0 = level0[std::size_t(x) + e.x * (std::size_t(y) + e.y * std::size_t(z))];
        if (std::isnan(v0)) continue;
        const std::int64_t p0[3] = {x, y, z};
        int i0[3];
        double w[3];
        for (int a = 0; a < 3; ++a) {
          const double u = (double(p0[a] - (core.lo[a] << f[a])) + 0.5) / double(1u << f[a]) +
                           double(layout.halo) - 0.5;
          const double c = std::clamp(u, 0.0, double(ps[a] - 1));
          i0[a] = std::min(int(c), int(ps[a]) - 2);
          w[a] = c - i0[a];
        }
        double r = 0.0;
        for (int k = 0; k < 8; ++k) {
          const int d[3] = {k & 1, (k >> 1) & 1, (k >> 2) & 1};
          double wk = 1.0;
          for (int a = 0; a < 3; ++a) wk *= d[a] ? w[a] : 1.0 - w[a];
          if (wk != 0.0) r += wk * coarse(i0[0] + d[0], i0[1] + d[1], i0[2] + d[2]);
        }
        if (!std::isnan(r)) worst = std::max(worst, std::abs(r - v0));
      }
    }
  }
  const ValueRange range = s.volume().range(key.channel());
  return std::min(1.0, worst / (range.hi - range.lo));
}

// Every brick of every coarse level of volumes whose extents are no multiple of the brick, against
// the definition: exactly for u8 (weights of 2^-k and small integers are exact in doubles, in any
// order), to rounding for f32 with NaN voxels.
TEST(BrickError, EveryCoarseBrickIsTheDefinitionsError) {
  const glm::u64vec3 e(37, 29, 23);
  const std::size_t n = std::size_t(e.x * e.y * e.z);
  std::mt19937 rng(11);
  std::vector<std::uint8_t> bytes(n);
  std::vector<float> floats(n);
  std::vector<double> bytes_d(n), floats_d(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Smooth along x (so that codes vary), noisy elsewhere.
    bytes[i] = std::uint8_t((i % e.x) * 6 + rng() % 16);
    floats[i] = rng() % 97 == 0
                    ? std::numeric_limits<float>::quiet_NaN()
                    : float(std::sin(double(i % e.x) * 0.3) + double(rng() % 100) * 1e-3);
    bytes_d[i] = bytes[i];
    floats_d[i] = floats[i];
  }
  const InMemorySource s8 = source_of(e, VoxelType::u8, bytes);
  const InMemorySource s32 = source_of(e, VoxelType::f32, floats);
  int checked = 0;
  for (std::uint32_t l = 1; l < s8.hierarchy().level_count(); ++l) {
    const glm::uvec3 nb = s8.hierarchy().level(l).bricks;
    for (std::uint32_t z = 0; z < nb.z; ++z) {
      for (std::uint32_t y = 0; y < nb.y; ++y) {
        for (std::uint32_t x = 0; x < nb.x; ++x) {
          const BrickKey key(l, 0, {x, y, z});
          ASSERT_EQ(error_of(s8, key), reference_error(s8, bytes_d, key)) << "u8 level " << l;
          const double ref = reference_error(s32, floats_d, key);
          ASSERT_NEAR(error_of(s32, key), ref, 1e-12 * (1.0 + ref)) << "f32 level " << l;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 8);
}

TEST(BrickError, AboveTheBudgetTheRegionSpreadBoundsIt) {
  const InMemorySource s = ramp();
  const BrickKey key(1, 0, {1, 0, 0});
  const double measured = error_of(s, key);
  const double bound = error_of(s, key, 0);
  // Level-0 x of the brick: [16, 32), dilated by one level-1 voxel: [14, 34).
  EXPECT_GE(bound, 19.0 / 64.0 - 1e-6);
  EXPECT_LE(bound, 1.0);
  EXPECT_GE(bound, measured);
}

// Counts level-0 reads of an inner source.
class Level0Reads final : public BrickSource {
 public:
  explicit Level0Reads(const BrickSource& inner) : inner_(inner) {}
  const BrickHierarchy& hierarchy() const override { return inner_.hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    if (key.level() == 0) ++reads;
    inner_.read_brick(key, out);
  }
  RegionMeta region_meta(std::uint32_t c, const Box3& b) const override {
    return inner_.region_meta(c, b);
  }
  std::string name() const override { return "level0-reads"; }
  mutable int reads = 0;

 private:
  const BrickSource& inner_;
};

TEST(BrickError, ConstantRegionsAreAnsweredFromMetadataWithoutReads) {
  // Zero below x = 32, a ramp above: the coarse brick over the zeros is exact without reading
  // level 0, the one over the ramp is measured.
  const glm::u64vec3 e(64, 16, 16);
  std::vector<float> v(std::size_t(e.x * e.y * e.z));
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double x = double(i % e.x);
    v[i] = x < 32 ? 0.0f : float((x * x) / 4096.0);
  }
  const InMemorySource inner = source_of(e, VoxelType::f32, v);
  const Level0Reads s(inner);
  EXPECT_EQ(error_of(s, BrickKey(1, 0, {0, 0, 0})), 0.0);
  EXPECT_EQ(s.reads, 0);
  EXPECT_GT(error_of(s, BrickKey(1, 0, {3, 0, 0})), 1e-5);
  EXPECT_GT(s.reads, 0);
}

TEST(BrickError, KeptAsFloatItNeverShrinks) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-30.0, 0.0);
  for (int i = 0; i < 10000; ++i) {
    const double e = std::exp2(u(rng));
    const float f = brick_error_to_float(e);
    ASSERT_GE(double(f), e);
    ASSERT_LT(double(std::nextafter(f, 0.0f)), e);  // the least such float
    ASSERT_LE(brick_error_code(double(f)), brick_error_code(e));
  }
  EXPECT_EQ(brick_error_to_float(0.0), 0.0f);
  EXPECT_EQ(brick_error_to_float(std::ldexp(1.0, -7)), std::ldexp(1.0f, -7));
  EXPECT_TRUE(std::isnan(brick_error_to_float(std::nan(""))));
  // Rounding to nearest would turn 2^-7 + tiny into exactly 2^-7, whose code claims 7.
  EXPECT_EQ(brick_error_code(brick_error_to_float(std::ldexp(1.0, -7) * (1 + 1e-12))), 6u);
}

TEST(BrickError, RejectsAWronglySizedBuffer) {
  const InMemorySource s = ramp();
  std::vector<std::byte> small(10);
  EXPECT_RESOCT_ERROR(measure_brick_error(s, BrickKey(1, 0, {0, 0, 0}), small),
                      ErrorCode::invalid_argument, "padded");
}

}  // namespace
