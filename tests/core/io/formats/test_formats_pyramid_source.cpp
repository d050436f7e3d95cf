// PyramidSource (coarser levels on demand) against InMemorySource (every level computed up
// front by whole-level downsampling): identical bricks and region metadata, with and without a
// cache, with stored levels supplied by the input, and with data-derived ranges.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/io/formats/channel_stack.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/sources/brick_error.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "support/brick_compare.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

DenseVolume random_volume(const glm::u64vec3& e, VoxelType t, std::uint32_t channels,
                          std::uint32_t seed) {
  VolumeDesc d;
  d.extent = e;
  d.type = t;
  d.channels = channels;
  std::mt19937 rng(seed);
  const std::size_t n = std::size_t(e.x * e.y * e.z) * channels;
  std::vector<std::byte> bytes(n * voxel_size(t));
  for (std::size_t i = 0; i < n; ++i) {
    // Smooth structure plus noise, so that averages and occupancy both vary.
    const double s = 0.5 + 0.4 * std::sin(double(i % 977) * 0.01) * double(rng() % 100) / 100.0;
    if (t == VoxelType::u8) {
      bytes[i] = std::byte(std::uint8_t(s * 255.0));
    } else if (t == VoxelType::u16) {
      const auto v = std::uint16_t(s * 65535.0);
      std::memcpy(bytes.data() + 2 * i, &v, 2);
    } else {
      float v = float(s * 10.0 - 3.0);
      if (rng() % 40 == 0) v = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(bytes.data() + 4 * i, &v, 4);
    }
  }
  return DenseVolume::from_bytes(d, std::move(bytes));
}

struct Case {
  glm::u64vec3 extent;
  VoxelType type;
  std::uint32_t channels;
  glm::uvec3 brick;
  std::uint32_t halo;
};

class PyramidSourceCases : public ::testing::TestWithParam<Case> {};

TEST_P(PyramidSourceCases, BricksAndRegionMetaEqualEagerLevels) {
  const Case c = GetParam();
  const DenseVolume v = random_volume(c.extent, c.type, c.channels, 7);
  const BrickLayout layout{c.brick, c.halo};
  const InMemorySource eager(v, layout, 8, "eager");
  for (std::uint64_t cache : {std::uint64_t(64) << 20, std::uint64_t(0)}) {
    PyramidSourceOptions o;
    o.cache_bytes = cache;
    o.metadata_block = 8;
    o.threads = 2;
    const auto lazy = make_dense_pyramid_source(v, layout, "lazy", o);
    ASSERT_GT(lazy->hierarchy().level_count(), 2u);
    EXPECT_FALSE(lazy->stored_level(1));
    test::expect_same_bricks(eager, *lazy);
    std::mt19937 rng(3);
    for (int i = 0; i < 50; ++i) {
      Box3 r;
      for (int a = 0; a < 3; ++a) {
        const auto e = std::int64_t(c.extent[a]);
        r.lo[a] = std::int64_t(rng() % std::uint64_t(e));
        r.hi[a] = r.lo[a] + 1 + std::int64_t(rng() % std::uint64_t(e));
      }
      for (std::uint32_t ch = 0; ch < c.channels; ++ch) {
        EXPECT_EQ(eager.region_meta(ch, r), lazy->region_meta(ch, r));
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, PyramidSourceCases,
    ::testing::Values(Case{{37, 29, 23}, VoxelType::u8, 1, glm::uvec3(4), 1},
                      Case{{45, 40, 9}, VoxelType::u16, 2, glm::uvec3(8, 8, 4), 2},
                      Case{{33, 17, 50}, VoxelType::f32, 1, glm::uvec3(6, 5, 4), 1},
                      Case{{64, 64, 64}, VoxelType::u8, 1, glm::uvec3(8), 0}));

TEST(PyramidSource, StoredLevelsAreReadNotComputed) {
  const DenseVolume v = random_volume({40, 36, 30}, VoxelType::u16, 1, 11);
  const BrickLayout layout{glm::uvec3(8), 1};
  const InMemorySource eager(v, layout, 16, "eager");
  const BrickHierarchy& h = eager.hierarchy();
  // Level 1 "stored" by the input: served from the eager copy; a counter proves it is used.
  auto reads = std::make_shared<std::atomic<int>>(0);
  auto reader = [&eager, &h, reads](std::uint32_t level) {
    return [&eager, &h, level, reads](std::uint32_t c, const Box3& box, std::span<std::byte> out) {
      ++*reads;
      const Box3 whole{glm::i64vec3(0), glm::i64vec3(h.level(level).extent)};
      copy_box_clamped(eager.level_voxels(level, c), whole, out, box, 2);
    };
  };
  const auto lazy = std::make_unique<PyramidSource>(
      v.desc(), layout, std::vector<LevelBoxReader>{reader(0), reader(1)}, "stored");
  EXPECT_TRUE(lazy->stored_level(1));
  EXPECT_FALSE(lazy->stored_level(2));
  test::expect_same_bricks(eager, *lazy);
  EXPECT_GT(reads->load(), 0);
}

TEST(PyramidSource, CacheServesRepeatedCoarseReads) {
  const DenseVolume v = random_volume({32, 32, 32}, VoxelType::u8, 1, 5);
  const auto s = make_dense_pyramid_source(v, BrickLayout{glm::uvec3(8), 1}, "c");
  std::vector<std::byte> out(s->hierarchy().layout().padded_voxels());
  s->read_brick(BrickKey(2, 0, {0, 0, 0}), out);
  const auto first = s->cache_stats();
  s->read_brick(BrickKey(2, 0, {0, 0, 0}), out);
  const auto second = s->cache_stats();
  EXPECT_GT(second.hits, first.hits);
  EXPECT_EQ(second.insertions, first.insertions);
}

// OME-Zarr, NIfTI, NRRD and TIFF sources are PyramidSources: a coarse brick's error is measured
// once per source and then answered from the cache, however often the brick loads again.
TEST(PyramidSource, BrickErrorsAreMeasuredOnceAndCached) {
  const DenseVolume v = random_volume({32, 32, 32}, VoxelType::u8, 2, 9);
  const std::shared_ptr<const PyramidSource> s =
      make_dense_pyramid_source(v, BrickLayout{glm::uvec3(8), 1}, "e");
  std::vector<std::byte> out(s->hierarchy().layout().padded_voxels());
  const BrickKey key(1, 1, {1, 0, 1});
  s->read_brick(key, out);
  const double want = measure_brick_error(*s, key, out);
  EXPECT_GT(want, 0.0);
  EXPECT_EQ(s->brick_error(key, out), want);
  EXPECT_EQ(s->brick_errors_measured(), 1u);
  EXPECT_EQ(s->brick_error(key, out), want);
  EXPECT_EQ(s->brick_errors_measured(), 1u);
  EXPECT_EQ(s->brick_error(BrickKey(0, 1, {1, 0, 1}), out), 0.0);  // level 0: nothing to measure
  EXPECT_EQ(s->brick_errors_measured(), 1u);
  // A stack of channels answers with its member's own (cached) value.
  const std::shared_ptr<const BrickSource> other = make_dense_pyramid_source(
      random_volume({32, 32, 32}, VoxelType::u8, 1, 4), BrickLayout{glm::uvec3(8), 1}, "o");
  const auto stack = stack_channels({other, s}, "stack");
  EXPECT_EQ(stack->brick_error(BrickKey(1, 2, {1, 0, 1}), out), want);
  EXPECT_EQ(s->brick_errors_measured(), 1u);
  std::vector<std::byte> small(3);
  EXPECT_RESOCT_ERROR(s->brick_error(key, small), ErrorCode::invalid_argument, "out");
  EXPECT_RESOCT_ERROR(stack->brick_error(BrickKey(1, 3, {0, 0, 0}), out), ErrorCode::out_of_range,
                      "stack");
}

TEST(PyramidSource, RangesFromData) {
  VolumeDesc d;
  d.extent = {5, 4, 3};
  d.type = VoxelType::f32;
  std::vector<float> vals(60, 2.0f);
  vals[7] = -1.5f;
  vals[9] = 7.25f;
  vals[11] = std::numeric_limits<float>::infinity();
  vals[12] = std::numeric_limits<float>::quiet_NaN();
  PyramidSourceOptions o;
  o.ranges_from_data = true;
  const auto s = make_dense_pyramid_source(DenseVolume::from_values(d, vals),
                                           BrickLayout{glm::uvec3(4), 1}, "r", o);
  EXPECT_EQ(s->volume().range(0), (ValueRange{-1.5, 7.25}));
  EXPECT_EQ(data_value_range(3.0, 3.0), (ValueRange{3.0, 4.0}));
  EXPECT_EQ(data_value_range(std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()),
            (ValueRange{0.0, 1.0}));
}

TEST(PyramidSource, BadArguments) {
  const DenseVolume v = random_volume({8, 8, 8}, VoxelType::u8, 1, 1);
  EXPECT_RESOCT_ERROR(PyramidSource(v.desc(), {}, {}, "x"), ErrorCode::invalid_argument, "levels");
  PyramidSourceOptions o;
  o.metadata_block = 12;
  EXPECT_RESOCT_ERROR(make_dense_pyramid_source(v, {}, "x", o), ErrorCode::invalid_argument,
                      "metadata_block");
  o.metadata_block = 16;
  o.error_cache_entries = 0;
  EXPECT_RESOCT_ERROR(make_dense_pyramid_source(v, {}, "x", o), ErrorCode::invalid_argument,
                      "error_cache_entries");
  const auto s = make_dense_pyramid_source(v, BrickLayout{glm::uvec3(4), 1}, "x");
  std::vector<std::byte> out(8);
  EXPECT_RESOCT_ERROR(s->read_level_box(0, 0, Box3{{0, 0, 0}, {2, 2, 3}}, out),
                      ErrorCode::invalid_argument, "out");
  EXPECT_RESOCT_ERROR(s->read_level_box(0, 0, Box3{{0, 0, 0}, {9, 1, 1}}, out),
                      ErrorCode::invalid_argument, "box");
  EXPECT_RESOCT_ERROR(s->read_level_box(9, 0, Box3{{0, 0, 0}, {1, 1, 1}}, out),
                      ErrorCode::invalid_argument, "level");
}

}  // namespace
