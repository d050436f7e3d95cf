// measure_brick_error(): the measured down-sampling error of a coarse brick (the largest difference
// between the level's trilinear reconstruction and the level-0 voxels, at their centres), its
// region-spread bound above the budget, and the page entry's error code.
#include <gtest/gtest.h>

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
