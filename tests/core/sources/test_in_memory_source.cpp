#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "support/expect_error.hpp"
#include "support/reference_levels.hpp"

using namespace resoct;

namespace {

// Level-0 test data: smooth-ish gradients plus noise, and for f32 a sprinkling of NaN.
std::vector<double> make_values(const glm::u64vec3& e, VoxelType t, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<double> v(std::size_t(e.x * e.y * e.z));
  const double top = t == VoxelType::u8 ? 255.0 : t == VoxelType::u16 ? 65535.0 : 1.0;
  std::size_t i = 0;
  for (std::uint64_t z = 0; z < e.z; ++z)
    for (std::uint64_t y = 0; y < e.y; ++y)
      for (std::uint64_t x = 0; x < e.x; ++x, ++i) {
        const double s = 0.5 + 0.25 * std::sin(0.3 * double(x) + 0.2 * double(y)) +
                         0.2 * double(z) / double(e.z) + 0.05 * double(rng() % 1000) / 1000.0;
        // Sparse zero regions so that empty bins and zero minima occur.
        const bool hole = (x / 9 + y / 7 + z / 5) % 4 == 0;
        double val = hole ? 0.0 : s * top;
        if (t != VoxelType::f32) val = std::floor(std::min(val, top));
        if (t == VoxelType::f32 && rng() % 50 == 0) val = std::numeric_limits<double>::quiet_NaN();
        if (t == VoxelType::f32 && !std::isnan(val)) val = double(float(val));
        v[i] = val;
      }
  return v;
}

DenseVolume make_volume(const glm::u64vec3& e, VoxelType t, std::uint32_t channels,
                        std::vector<std::vector<double>>& values) {
  VolumeDesc d;
  d.extent = e;
  d.type = t;
  d.channels = channels;
  const std::size_t n = std::size_t(e.x * e.y * e.z);
  std::vector<std::byte> bytes(n * channels * voxel_size(t));
  values.clear();
  for (std::uint32_t c = 0; c < channels; ++c) {
    values.push_back(make_values(e, t, 17 + c));
    for (std::size_t i = 0; i < n; ++i) {
      std::byte* p = bytes.data() + (c * n + i) * voxel_size(t);
      const double v = values[c][i];
      if (t == VoxelType::u8) *p = std::byte(std::uint8_t(v));
      if (t == VoxelType::u16) {
        const std::uint16_t u = std::uint16_t(v);
        std::memcpy(p, &u, 2);
      }
      if (t == VoxelType::f32) {
        const float f = float(v);
        std::memcpy(p, &f, 4);
      }
    }
  }
  return DenseVolume::from_bytes(d, std::move(bytes));
}

bool same(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

}  // namespace

TEST(InMemorySource, EveryVoxelOfEveryBrickAtEveryLevelMatchesTheDefinition) {
  const glm::u64vec3 e{40, 33, 17};
  for (VoxelType t : {VoxelType::u8, VoxelType::u16, VoxelType::f32}) {
    std::vector<std::vector<double>> values;
    const DenseVolume dense = make_volume(e, t, 2, values);
    for (std::uint32_t halo = 0; halo <= 2; ++halo) {
      const InMemorySource src(dense, BrickLayout{glm::uvec3(8), halo});
      const BrickHierarchy& h = src.hierarchy();
      ASSERT_GE(h.level_count(), 3u);
      for (std::uint32_t c = 0; c < 2; ++c) {
        const std::vector<test::RefLevel> ref = test::reference_levels(h, values[c], t);
        std::vector<std::byte> buf(h.layout().padded_voxels() * voxel_size(t));
        for (std::uint32_t l = 0; l < h.level_count(); ++l) {
          const LevelInfo& li = h.level(l);
          for (std::uint32_t bz = 0; bz < li.bricks.z; ++bz)
            for (std::uint32_t by = 0; by < li.bricks.y; ++by)
              for (std::uint32_t bx = 0; bx < li.bricks.x; ++bx) {
                src.read_brick(BrickKey(l, c, {bx, by, bz}), buf);
                const glm::i64vec3 origin =
                    glm::i64vec3(bx, by, bz) * glm::i64vec3(8) - glm::i64vec3(halo);
                const glm::i64vec3 p(h.layout().padded_size());
                std::size_t i = 0;
                for (std::int64_t z = 0; z < p.z; ++z)
                  for (std::int64_t y = 0; y < p.y; ++y)
                    for (std::int64_t x = 0; x < p.x; ++x, ++i) {
                      const std::int64_t gx = test::clamp_index(origin.x + x, li.extent.x);
                      const std::int64_t gy = test::clamp_index(origin.y + y, li.extent.y);
                      const std::int64_t gz = test::clamp_index(origin.z + z, li.extent.z);
                      const double want = ref[l].at(gx, gy, gz);
                      const double got = test::voxel_as_double(buf.data(), i, t);
                      ASSERT_TRUE(same(got, want))
                          << to_string(t) << " halo " << halo << " level " << l << " brick " << bx
                          << "," << by << "," << bz << " voxel " << x << "," << y << "," << z
                          << ": got " << got << " want " << want;
                    }
              }
        }
      }
    }
  }
}

TEST(InMemorySource, RegionMetaIsConservative) {
  const glm::u64vec3 e{40, 33, 17};
  std::mt19937 rng(99);
  for (VoxelType t : {VoxelType::u8, VoxelType::u16, VoxelType::f32}) {
    std::vector<std::vector<double>> values;
    const InMemorySource src(make_volume(e, t, 2, values), BrickLayout{glm::uvec3(8), 1}, 4);
    for (int trial = 0; trial < 300; ++trial) {
      const std::uint32_t c = rng() % 2;
      Box3 b;
      for (int a = 0; a < 3; ++a) {
        // Regions may stick out of the volume: the query clamps them.
        b.lo[a] = std::int64_t(rng() % (e[a] + 4)) - 2;
        b.hi[a] = b.lo[a] + 1 + std::int64_t(rng() % e[a]);
      }
      const RegionMeta m = src.region_meta(c, b);
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      std::uint32_t occ = 0;
      const ValueRange r = src.volume().range(c);
      for (std::int64_t z = std::max<std::int64_t>(b.lo.z, 0);
           z < std::min<std::int64_t>(b.hi.z, e.z); ++z)
        for (std::int64_t y = std::max<std::int64_t>(b.lo.y, 0);
             y < std::min<std::int64_t>(b.hi.y, e.y); ++y)
          for (std::int64_t x = std::max<std::int64_t>(b.lo.x, 0);
               x < std::min<std::int64_t>(b.hi.x, e.x); ++x) {
            const double v = values[c][std::size_t((z * e.y + y) * e.x + x)];
            if (std::isnan(v)) continue;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            occ |= occupancy_bit(v, r);
          }
      EXPECT_LE(m.min, lo) << trial;
      EXPECT_GE(m.max, hi) << trial;
      EXPECT_EQ(m.occupancy & occ, occ) << trial;
    }
    // Outside the volume: the "only NaN" summary.
    EXPECT_EQ(src.region_meta(0, Box3{{100, 0, 0}, {120, 5, 5}}), RegionMeta{});
  }
}

TEST(InMemorySource, BrickMetaMatchesBruteForce) {
  std::vector<std::vector<double>> values;
  const InMemorySource src(make_volume({40, 33, 17}, VoxelType::f32, 1, values),
                           BrickLayout{glm::uvec3(8), 1});
  const BrickHierarchy& h = src.hierarchy();
  const std::vector<test::RefLevel> ref = test::reference_levels(h, values[0], VoxelType::f32);
  for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i) {
    const BrickKey k = h.key_from_linear(0, i);
    const LevelInfo& li = h.level(k.level());
    const Box3 p = h.padded_box(k.level(), k.brick());
    BrickMeta want;
    bool first = true;
    double first_v = 0;
    for (std::int64_t z = p.lo.z; z < p.hi.z; ++z)
      for (std::int64_t y = p.lo.y; y < p.hi.y; ++y)
        for (std::int64_t x = p.lo.x; x < p.hi.x; ++x) {
          const double v = ref[k.level()].at(test::clamp_index(x, li.extent.x),
                                             test::clamp_index(y, li.extent.y),
                                             test::clamp_index(z, li.extent.z));
          if (std::isnan(v)) continue;
          if (first) first_v = v;
          if (!first && v != first_v) want.constant = false;
          first = false;
          want.min = std::min(want.min, v);
          want.max = std::max(want.max, v);
        }
    EXPECT_EQ(src.brick_meta(k), want) << "brick " << i;
  }
}

TEST(InMemorySource, ExternalStorageAndConcurrentReadsAgree) {
  std::vector<std::vector<double>> values;
  const DenseVolume owned = make_volume({40, 33, 17}, VoxelType::u16, 1, values);
  auto mapping =
      std::make_shared<std::vector<std::byte>>(owned.bytes().begin(), owned.bytes().end());
  const DenseVolume external =
      DenseVolume::from_pointer(owned.desc(), mapping->data(), mapping->size(), mapping);
  mapping.reset();  // the volume keeps the "mapping" alive
  EXPECT_EQ(external.at<std::uint16_t>(0, {3, 4, 5}),
            std::uint16_t(values[0][(5 * 33 + 4) * 40 + 3]));
  EXPECT_EQ(external.value(0, {39, 32, 16}), values[0].back());
  const InMemorySource a(owned, BrickLayout{glm::uvec3(8), 2});
  const InMemorySource b(external, BrickLayout{glm::uvec3(8), 2});
  const BrickHierarchy& h = a.hierarchy();
  const std::size_t bytes = h.layout().padded_voxels() * 2;
  std::vector<std::thread> threads;
  std::vector<int> mismatches(4, 0);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      std::vector<std::byte> x(bytes), y(bytes);
      for (std::uint64_t i = std::uint64_t(t); i < h.bricks_per_channel(); i += 4) {
        const BrickKey k = h.key_from_linear(0, i);
        a.read_brick(k, x);
        b.read_brick(k, y);
        mismatches[std::size_t(t)] += x != y;
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
}

TEST(InMemorySource, RejectsBadInput) {
  std::vector<std::vector<double>> values;
  const DenseVolume dense = make_volume({20, 10, 6}, VoxelType::u16, 2, values);
  const InMemorySource src(dense, BrickLayout{glm::uvec3(8), 1});
  std::vector<std::byte> wrong(src.hierarchy().layout().padded_voxels());  // u16 needs twice this
  EXPECT_RESOCT_ERROR(src.read_brick(BrickKey(0, 0, {0, 0, 0}), wrong), ErrorCode::invalid_argument,
                      "out");
  std::vector<std::byte> right(src.hierarchy().layout().padded_voxels() * 2);
  EXPECT_RESOCT_ERROR(src.read_brick(BrickKey(0, 0, {3, 0, 0}), right), ErrorCode::out_of_range,
                      "brick 3,0,0");
  EXPECT_RESOCT_ERROR(src.read_brick(BrickKey(0, 2, {0, 0, 0}), right), ErrorCode::out_of_range,
                      "channel 2");
  EXPECT_RESOCT_ERROR(src.read_brick(BrickKey(src.hierarchy().level_count(), 0, {0, 0, 0}), right),
                      ErrorCode::out_of_range, "level");
  EXPECT_RESOCT_ERROR(src.region_meta(5, Box3{{0, 0, 0}, {1, 1, 1}}), ErrorCode::out_of_range,
                      "channel");
  VolumeDesc d = dense.desc();
  EXPECT_RESOCT_ERROR(DenseVolume::from_bytes(d, std::vector<std::byte>(7)),
                      ErrorCode::invalid_argument, "data");
  EXPECT_RESOCT_ERROR(DenseVolume::from_pointer(d, nullptr, 0, nullptr),
                      ErrorCode::invalid_argument, "data");
  EXPECT_RESOCT_ERROR(dense.at<float>(0, {0, 0, 0}), ErrorCode::invalid_argument, "T");
  EXPECT_RESOCT_ERROR(dense.value(0, {20, 0, 0}), ErrorCode::out_of_range, "p");
  EXPECT_RESOCT_ERROR(InMemorySource(DenseVolume{}), ErrorCode::invalid_argument, "volume");
  EXPECT_RESOCT_ERROR(InMemorySource(dense, BrickLayout{glm::uvec3(8), 1}, 12),
                      ErrorCode::invalid_argument, "metadata_block");
}
