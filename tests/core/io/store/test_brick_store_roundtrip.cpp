// Round trips through the brick store: every brick, every brick's metadata and region metadata
// must come back exactly as the source defines them, for every voxel type and codec.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <thread>

#include "resoct/io/store/brick_store.hpp"
#include "support/expect_error.hpp"
#include "support/function_source.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::FunctionSource;
using resoct::test::TempDir;

namespace {

struct RoundTripCase {
  VoxelType type;
  Codec codec;
  int level;
  glm::uvec3 brick;
  std::uint32_t halo;
  std::uint32_t channels;
  std::uint32_t metadata_block;
};

std::string case_name(const ::testing::TestParamInfo<RoundTripCase>& info) {
  const RoundTripCase& c = info.param;
  return std::string(to_string(c.type)) + "_" + std::string(to_string(c.codec)) + "_l" +
         std::to_string(c.level < 0 ? 100 - c.level : c.level) + "_b" + std::to_string(c.brick.x) +
         "x" + std::to_string(c.brick.y) + "x" + std::to_string(c.brick.z) + "_h" +
         std::to_string(c.halo) + "_c" + std::to_string(c.channels) + "_m" +
         std::to_string(c.metadata_block);
}

FunctionSource make_source(VoxelType type, std::uint32_t channels, glm::u64vec3 extent,
                           BrickLayout layout, bool explicit_ranges) {
  VolumeDesc v;
  v.extent = extent;
  v.spacing = {1.0, 0.5, 2.0};
  v.channels = channels;
  v.type = type;
  if (explicit_ranges) {
    for (std::uint32_t c = 0; c < channels; ++c) {
      v.ranges.push_back(type == VoxelType::f32 ? ValueRange{-0.25, 0.8 + 0.1 * c}
                                                : ValueRange{10.0 * c, 180.0 + 1000.0 * c});
    }
  }
  return FunctionSource(v, layout, [type, extent](std::uint32_t c, const glm::u64vec3& p) {
    return test::test_value(type, c, p, extent);
  });
}

std::vector<std::byte> read(const BrickSource& s, BrickKey k) {
  std::vector<std::byte> b(s.hierarchy().layout().padded_voxels() * voxel_size(s.volume().type));
  s.read_brick(k, b);
  return b;
}

std::vector<BrickKey> all_keys(const BrickHierarchy& h) {
  std::vector<BrickKey> keys;
  for (std::uint32_t c = 0; c < h.volume().channels; ++c) {
    for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i)
      keys.push_back(h.key_from_linear(c, i));
  }
  return keys;
}

class BrickStoreRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(BrickStoreRoundTrip, BricksMetaAndRegionsComeBackExactly) {
  const RoundTripCase& tc = GetParam();
  const glm::u64vec3 extent(40, 33, 17);
  const FunctionSource src =
      make_source(tc.type, tc.channels, extent, BrickLayout{tc.brick, tc.halo}, tc.channels != 2);
  TempDir dir;
  const std::string path = dir.file("vol.rbs");
  StoreWriteOptions opt;
  opt.codec = tc.codec;
  opt.level = tc.level;
  opt.metadata_block = tc.metadata_block;
  opt.threads = 3;
  const StoreSummary summary = write_brick_store(src, path, opt);
  const BrickStoreSource store(path);

  EXPECT_TRUE(store.hierarchy() == src.hierarchy());
  EXPECT_EQ(store.volume(), src.volume());  // ranges (explicit or default) and spacing too
  EXPECT_EQ(store.name(), path);
  EXPECT_EQ(store.metadata_block(), tc.metadata_block);

  std::uint64_t constant = 0, empty = 0;
  for (const BrickKey k : all_keys(src.hierarchy())) {
    const std::vector<std::byte> want = read(src, k);
    ASSERT_EQ(read(store, k), want) << "level " << k.level() << " channel " << k.channel();
    const BrickMeta m = scan_brick(want, src.volume().type);
    EXPECT_EQ(store.brick_meta(k), m);
    const std::size_t vs = voxel_size(src.volume().type);
    bool same = true;
    for (std::size_t i = vs; i < want.size() && same; i += vs)
      same = std::memcmp(want.data(), want.data() + i, vs) == 0;
    constant += same;
    empty += m.all_zero();
  }
  // The test data has an all-zero slab, so constant bricks really occur and must be counted.
  EXPECT_GT(constant, 0u);
  const StoreLevelStats total = store.stats().total();
  EXPECT_EQ(total.constant_bricks, constant);
  EXPECT_EQ(total.empty_bricks, empty);
  EXPECT_EQ(total.brick_count, src.hierarchy().bricks_per_channel() * tc.channels);
  EXPECT_EQ(total.uncompressed_bytes, total.brick_count * src.hierarchy().layout().padded_voxels() *
                                          voxel_size(src.volume().type));
  const std::vector<std::uint8_t> file = test::read_bytes(path);
  EXPECT_EQ(total.compressed_bytes, test::get_le(file, test::layout::payload_size, 8));
  EXPECT_EQ(store.stats().file_bytes, file.size());
  ASSERT_EQ(summary.stats.levels.size(), store.stats().levels.size());
  for (std::size_t l = 0; l < summary.stats.levels.size(); ++l) {
    const StoreLevelStats& a = summary.stats.levels[l];
    const StoreLevelStats& b = store.stats().levels[l];
    EXPECT_EQ(a.brick_count, b.brick_count);
    EXPECT_EQ(a.compressed_bytes, b.compressed_bytes);
    EXPECT_EQ(a.constant_bricks, b.constant_bricks);
    EXPECT_EQ(a.empty_bricks, b.empty_bricks);
    EXPECT_EQ(b.extent, src.hierarchy().level(std::uint32_t(l)).extent);
  }

  // Block-aligned regions of at most 64 blocks are answered from the finest blocks: exact.
  const std::int64_t mb = tc.metadata_block;
  std::mt19937 rng(1234);
  for (std::uint32_t c = 0; c < tc.channels; ++c) {
    for (int i = 0; i < 40; ++i) {
      glm::i64vec3 lo, hi;
      for (int a = 0; a < 3; ++a) {
        const std::int64_t nb = (std::int64_t(extent[a]) + mb - 1) / mb;
        lo[a] = std::int64_t(rng() % std::uint32_t(nb));
        hi[a] = std::min<std::int64_t>(nb, lo[a] + 1 + std::int64_t(rng() % 4));
      }
      const Box3 aligned{lo * mb, hi * mb};
      EXPECT_EQ(store.region_meta(c, aligned), src.region_meta(c, aligned));
    }
    const Box3 whole{glm::i64vec3(-3), glm::i64vec3(extent) + std::int64_t(5)};
    EXPECT_EQ(store.region_meta(c, whole), src.region_meta(c, whole));
    // Arbitrary regions: conservative.
    for (int i = 0; i < 60; ++i) {
      glm::i64vec3 lo, hi;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::int64_t(rng() % std::uint32_t(extent[a]));
        hi[a] = lo[a] + 1 + std::int64_t(rng() % std::uint32_t(extent[a]));
      }
      const Box3 r{lo, hi};
      const RegionMeta got = store.region_meta(c, r);
      const RegionMeta want = src.region_meta(c, r);
      EXPECT_LE(got.min, want.min);
      EXPECT_GE(got.max, want.max);
      EXPECT_EQ(got.occupancy & want.occupancy, want.occupancy);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BrickStoreRoundTrip,
    ::testing::Values(RoundTripCase{VoxelType::u8, Codec::lz4, 0, glm::uvec3(8), 1, 2, 16},
                      RoundTripCase{VoxelType::u8, Codec::zstd, 19, glm::uvec3(16), 2, 1, 4},
                      RoundTripCase{VoxelType::u16, Codec::lz4, 9, glm::uvec3(16), 1, 3, 8},
                      RoundTripCase{VoxelType::u16, Codec::zstd, 0, glm::uvec3(8), 2, 2, 4},
                      RoundTripCase{VoxelType::f32, Codec::lz4, -4, glm::uvec3(8), 2, 2, 16},
                      RoundTripCase{VoxelType::f32, Codec::zstd, 0, glm::uvec3(16), 1, 3, 8},
                      RoundTripCase{VoxelType::u16, Codec::zstd, 3, glm::uvec3(8, 4, 16), 0, 1,
                                    32}),
    case_name);

TEST(BrickStore, ConstantNanAndZeroBricksStoreNoPayloadAndReadBackBitExact) {
  VolumeDesc v;
  v.extent = {32, 16, 8};
  v.type = VoxelType::f32;
  // With halo 1, x-bricks 0 and 1 are all NaN, x-brick 3 all -0.0 (bitwise constant, and zero
  // by value), x-brick 2 mixed.
  const FunctionSource src(v, BrickLayout{glm::uvec3(8), 1},
                           [](std::uint32_t, const glm::u64vec3& p) {
                             return p.x < 17 ? std::nan("") : p.x >= 23 ? -0.0 : double(p.y) + 1.0;
                           });
  TempDir dir;
  const std::string path = dir.file("nan.rbs");
  write_brick_store(src, path, StoreWriteOptions{});
  const BrickStoreSource store(path);
  const BrickHierarchy& h = src.hierarchy();
  for (std::uint32_t x = 0; x < 4; ++x) {
    const BrickKey k(0, 0, {x, 0, 0});
    EXPECT_EQ(read(store, k), read(src, k)) << x;
  }
  const BrickMeta nan_meta = store.brick_meta(BrickKey(0, 0, {0, 0, 0}));
  EXPECT_TRUE(nan_meta.constant);
  EXPECT_EQ(nan_meta.min, std::numeric_limits<double>::infinity());
  const BrickMeta zero_meta = store.brick_meta(BrickKey(0, 0, {3, 1, 0}));
  EXPECT_TRUE(zero_meta.all_zero());
  const StoreLevelStats& l0 = store.stats().levels[0];
  EXPECT_EQ(l0.brick_count, h.level(0).brick_count);
  // x-bricks 0, 1 (NaN) and 3 (-0.0) of each of the 2x1 (y, z) rows are constant.
  EXPECT_EQ(l0.constant_bricks, 3u * 2u);
  EXPECT_EQ(l0.empty_bricks, 2u);
  EXPECT_DOUBLE_EQ(l0.empty_fraction(), 2.0 / 8.0);
}

TEST(BrickStore, AllZeroVolumeHasNoPayloadBytes) {
  VolumeDesc v;
  v.extent = {20, 20, 20};
  v.type = VoxelType::u16;
  const FunctionSource src(v, BrickLayout{glm::uvec3(8), 1},
                           [](std::uint32_t, const glm::u64vec3&) { return 0.0; });
  TempDir dir;
  const std::string path = dir.file("zero.rbs");
  const StoreSummary s = write_brick_store(src, path, StoreWriteOptions{Codec::zstd});
  EXPECT_EQ(s.stats.total().compressed_bytes, 0u);
  EXPECT_TRUE(std::isinf(s.stats.total().compression_ratio()));
  const BrickStoreSource store(path);
  EXPECT_DOUBLE_EQ(store.stats().total().empty_fraction(), 1.0);
  for (const BrickKey k : all_keys(src.hierarchy())) EXPECT_EQ(read(store, k), read(src, k));
  const RegionMeta r = store.region_meta(0, Box3{glm::i64vec3(0), glm::i64vec3(20)});
  EXPECT_EQ(r.min, 0.0);
  EXPECT_EQ(r.max, 0.0);
  EXPECT_EQ(r.occupancy, 1u);
}

// A placed volume (a NIfTI's sform, an OME translation) keeps its origin through a store; an
// unplaced one writes no origin, so its header is the size it always was.
TEST(BrickStore, OriginIsKeptAndOnlyWrittenWhenNotZero) {
  VolumeDesc v;
  v.extent = {12, 10, 9};
  v.type = VoxelType::u8;
  TempDir dir;
  for (const glm::dvec3 origin : {glm::dvec3(0.0), glm::dvec3(-90.5, -125.5, 71.25)}) {
    v.origin = origin;
    const FunctionSource src(
        v, BrickLayout{glm::uvec3(8), 1},
        [](std::uint32_t, const glm::u64vec3& p) { return double(p.x + p.z); });
    const std::string path = dir.file("placed.rbs");
    write_brick_store(src, path, StoreWriteOptions{Codec::lz4});
    const BrickStoreSource store(path);
    EXPECT_EQ(store.volume(), v);
    const std::vector<std::uint8_t> bytes = test::read_bytes(path);
    const std::uint64_t header_size = test::get_le(bytes, test::layout::header_size, 4);
    EXPECT_EQ(header_size, origin == glm::dvec3(0.0) ? 188u + 16u : 188u + 16u + 24u);
    EXPECT_EQ(test::get_le(bytes, test::layout::flags, 4) & 2u,
              origin == glm::dvec3(0.0) ? 0u : 2u);
  }
}

TEST(BrickStore, FileDoesNotDependOnThreadCountAndProgressCountsEveryBrick) {
  const FunctionSource src =
      make_source(VoxelType::u16, 2, {40, 33, 17}, BrickLayout{glm::uvec3(8), 1}, true);
  TempDir dir;
  std::vector<std::uint64_t> seen;
  std::uint64_t total_seen = 0;
  StoreWriteOptions opt;
  opt.codec = Codec::zstd;
  opt.threads = 1;
  opt.progress = [&](std::uint64_t done, std::uint64_t total) {
    seen.push_back(done);
    total_seen = total;
  };
  write_brick_store(src, dir.file("one.rbs"), opt);
  const std::uint64_t bricks = src.hierarchy().bricks_per_channel() * 2;
  EXPECT_EQ(total_seen, bricks);
  ASSERT_EQ(seen.size(), bricks);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i + 1);
  opt.threads = 5;
  opt.progress = nullptr;
  write_brick_store(src, dir.file("five.rbs"), opt);
  EXPECT_EQ(test::read_bytes(dir.file("one.rbs")), test::read_bytes(dir.file("five.rbs")));
}

TEST(BrickStore, ConcurrentReadsMatchSingleThreaded) {
  const FunctionSource src =
      make_source(VoxelType::f32, 2, {40, 33, 17}, BrickLayout{glm::uvec3(8), 2}, true);
  TempDir dir;
  const std::string path = dir.file("mt.rbs");
  for (const Codec codec : {Codec::lz4, Codec::zstd}) {
    write_brick_store(src, path, StoreWriteOptions{codec});
    const BrickStoreSource store(path);
    const std::vector<BrickKey> keys = all_keys(store.hierarchy());
    std::vector<std::vector<std::byte>> single;
    for (const BrickKey k : keys) single.push_back(read(store, k));
    constexpr int kThreads = 4;
    std::vector<int> mismatches(kThreads, 0);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        // Each thread walks the keys in its own order, several times, so reads overlap.
        std::vector<std::size_t> order(keys.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::mt19937 rng(std::uint32_t(77 + t));
        for (int round = 0; round < 3; ++round) {
          std::shuffle(order.begin(), order.end(), rng);
          for (const std::size_t i : order) {
            if (read(store, keys[i]) != single[i]) ++mismatches[t];
            if (store.brick_meta(keys[i]) != scan_brick(single[i], VoxelType::f32)) ++mismatches[t];
          }
        }
      });
    }
    for (std::thread& t : threads) t.join();
    for (int t = 0; t < kThreads; ++t) EXPECT_EQ(mismatches[t], 0) << "thread " << t;
  }
}

TEST(BrickStore, RegionMetaRejectsBadChannelAndBrickMetaBadKey) {
  const FunctionSource src =
      make_source(VoxelType::u8, 1, {12, 12, 12}, BrickLayout{glm::uvec3(8), 1}, false);
  TempDir dir;
  const std::string path = dir.file("small.rbs");
  write_brick_store(src, path, StoreWriteOptions{});
  const BrickStoreSource store(path);
  EXPECT_RESOCT_ERROR(store.region_meta(1, Box3{glm::i64vec3(0), glm::i64vec3(4)}),
                      ErrorCode::invalid_argument, "channel");
  EXPECT_RESOCT_ERROR(store.brick_meta(BrickKey(0, 0, {5, 0, 0})), ErrorCode::out_of_range, path);
  std::vector<std::byte> small(7);
  EXPECT_RESOCT_ERROR(store.read_brick(BrickKey(0, 0, {0, 0, 0}), small),
                      ErrorCode::invalid_argument, "out");
}

}  // namespace
