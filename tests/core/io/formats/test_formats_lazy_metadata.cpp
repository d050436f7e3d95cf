// Lazy region metadata of PyramidSource (level 0 above eager_scan_voxels): answers are exact
// where blocks were computed (equal to the eager pyramid and to a brute-force scan of the
// touched blocks), conservative supersets of the region's voxels everywhere, and opening an
// OME-Zarr that declares 2^40 voxels reads only its metadata.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
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
    // Mostly a low floor with sparse spikes, so that regions differ in min, max and occupancy.
    const double s = rng() % 50 == 0 ? double(rng() % 1000) / 1000.0 : 0.1 * double(rng() % 3);
    if (t == VoxelType::u8) {
      bytes[i] = std::byte(std::uint8_t(s * 255.0));
    } else if (t == VoxelType::u16) {
      const auto v = std::uint16_t(s * 65535.0);
      std::memcpy(bytes.data() + 2 * i, &v, 2);
    } else {
      float v = float(s * 10.0 - 3.0);
      if (rng() % 30 == 0) v = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(bytes.data() + 4 * i, &v, 4);
    }
  }
  return DenseVolume::from_bytes(d, std::move(bytes));
}

/// The definition: min, max and occupancy of the non-NaN voxels of `box` (clamped).
RegionMeta brute(const DenseVolume& v, std::uint32_t c, Box3 box) {
  const VolumeDesc& d = v.desc();
  box = intersect(box, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)});
  RegionMeta m;
  for (std::int64_t z = box.lo.z; z < box.hi.z; ++z) {
    for (std::int64_t y = box.lo.y; y < box.hi.y; ++y) {
      for (std::int64_t x = box.lo.x; x < box.hi.x; ++x) {
        const glm::u64vec3 p(glm::i64vec3(x, y, z));
        double val = 0;
        switch (d.type) {
          case VoxelType::u8: val = double(v.at<std::uint8_t>(c, p)); break;
          case VoxelType::u16: val = double(v.at<std::uint16_t>(c, p)); break;
          case VoxelType::f32: val = double(v.at<float>(c, p)); break;
        }
        if (std::isnan(val)) continue;
        m.min = std::min(m.min, val);
        m.max = std::max(m.max, val);
        m.occupancy |= occupancy_bit(val, d.range(c));
      }
    }
  }
  return m;
}

/// `box` widened to the metadata blocks it touches.
Box3 block_aligned(const Box3& box, std::int64_t block) {
  return Box3{box.lo / block * block, (box.hi + (block - 1)) / block * block};
}

/// Claims nothing: the type's value range and every bin (the documented "unknown" answer).
RegionMeta unknown_answer(const VolumeDesc& d, std::uint32_t c) {
  const double inf = std::numeric_limits<double>::infinity();
  RegionMeta m;
  m.min = d.type == VoxelType::f32 ? -inf : 0.0;
  m.max = d.type == VoxelType::f32 ? inf : d.type == VoxelType::u8 ? 255.0 : 65535.0;
  m.occupancy = occupancy_span(m.min, m.max, d.range(c));
  return m;
}

bool covers(const RegionMeta& a, const RegionMeta& truth) {
  if (truth.min > truth.max) return true;  // nothing but NaN: any answer is conservative
  return a.min <= truth.min && a.max >= truth.max &&
         (a.occupancy & truth.occupancy) == truth.occupancy;
}

Box3 random_box(std::mt19937& rng, const glm::u64vec3& e, std::int64_t max_edge) {
  Box3 b;
  for (int a = 0; a < 3; ++a) {
    const auto ext = std::int64_t(e[a]);
    const std::int64_t len = 1 + std::int64_t(rng() % std::uint64_t(std::min(ext, max_edge)));
    b.lo[a] = std::int64_t(rng() % std::uint64_t(ext - len + 1));
    b.hi[a] = b.lo[a] + len;
  }
  return b;
}

class LazyCases : public ::testing::TestWithParam<VoxelType> {};

TEST_P(LazyCases, ExactWhereComputedConservativeEverywhere) {
  const glm::u64vec3 extent(37, 29, 23);  // 5 x 4 x 3 blocks of 8, partial at every far edge
  const DenseVolume v = random_volume(extent, GetParam(), 2, 11);
  const BrickLayout layout{glm::uvec3(8), 1};
  PyramidSourceOptions eo;
  eo.metadata_block = 8;
  eo.threads = 1;
  const auto eager = make_dense_pyramid_source(v, layout, "eager", eo);
  PyramidSourceOptions lo = eo;
  lo.eager_scan_voxels = 0;
  lo.lazy_query_blocks = 8;
  const auto lazy = make_dense_pyramid_source(v, layout, "lazy", lo);
  ASSERT_FALSE(eager->lazy_metadata());
  ASSERT_TRUE(lazy->lazy_metadata());
  EXPECT_EQ(lazy->lazy_blocks_computed(), 0u) << "nothing may be scanned at construction";

  const Box3 all{glm::i64vec3(0), glm::i64vec3(extent)};
  for (std::uint32_t c = 0; c < 2; ++c) {
    // Cold: the whole volume needs 60 unknown blocks, more than the read budget of 8.
    EXPECT_EQ(lazy->region_meta(c, all), unknown_answer(v.desc(), c));
  }
  std::mt19937 rng(5);
  std::uint64_t exact = 0, unknown = 0;
  for (int i = 0; i < 600; ++i) {
    const std::uint32_t c = std::uint32_t(rng() % 2);
    const Box3 box = random_box(rng, extent, i % 3 == 0 ? 37 : 12);
    const RegionMeta got = lazy->region_meta(c, box);
    const RegionMeta truth = brute(v, c, box);
    ASSERT_TRUE(covers(got, truth)) << "region " << i;
    if (got == unknown_answer(v.desc(), c)) {
      ++unknown;
      continue;
    }
    // Not unknown: the exact summary of the touched blocks, as the eager pyramid gives it
    // (these regions touch at most 64 blocks, its finest query level).
    ++exact;
    EXPECT_EQ(got, brute(v, c, block_aligned(box, 8))) << "region " << i;
    EXPECT_EQ(got, eager->region_meta(c, box)) << "region " << i;
  }
  EXPECT_GT(exact, 300u);
  EXPECT_GT(unknown, 0u);
  // Every block has been computed by now (small regions cover the volume), so the whole
  // volume, within the lookup limit of 8 * 8 blocks, is answered exactly from the cache.
  for (std::uint32_t c = 0; c < 2; ++c) {
    for (std::int64_t z = 0; z < 23; z += 8) {
      for (std::int64_t y = 0; y < 29; y += 8) {
        for (std::int64_t x = 0; x < 37; x += 8) {
          (void)lazy->region_meta(c, Box3{{x, y, z}, {x + 1, y + 1, z + 1}});
        }
      }
    }
    const std::uint64_t before = lazy->lazy_blocks_computed();
    EXPECT_EQ(lazy->region_meta(c, all), brute(v, c, all));
    EXPECT_EQ(lazy->region_meta(c, all), eager->region_meta(c, all));
    EXPECT_EQ(lazy->lazy_blocks_computed(), before) << "answered from the cache";
  }
  EXPECT_EQ(lazy->region_meta(0, Box3{{40, 0, 0}, {50, 5, 5}}), RegionMeta{})
      << "a region outside the volume holds nothing";
}

INSTANTIATE_TEST_SUITE_P(Types, LazyCases,
                         ::testing::Values(VoxelType::u8, VoxelType::u16, VoxelType::f32),
                         [](const auto& p) {
                           return std::string(p.param == VoxelType::u8    ? "u8"
                                              : p.param == VoxelType::u16 ? "u16"
                                                                          : "f32");
                         });

TEST(LazyMetadata, TinyCacheStaysConservativeAndExact) {
  const glm::u64vec3 extent(24, 24, 24);
  const DenseVolume v = random_volume(extent, VoxelType::u16, 1, 3);
  PyramidSourceOptions o;
  o.metadata_block = 4;
  o.eager_scan_voxels = 0;
  o.lazy_query_blocks = 27;
  o.lazy_cache_entries = 20;  // shards of one entry: nearly every lookup misses
  o.threads = 1;
  const auto lazy = make_dense_pyramid_source(v, BrickLayout{glm::uvec3(8), 1}, "lazy", o);
  std::mt19937 rng(9);
  for (int i = 0; i < 300; ++i) {
    const Box3 box = random_box(rng, extent, 9);
    const RegionMeta got = lazy->region_meta(0, box);
    ASSERT_TRUE(covers(got, brute(v, 0, box))) << "region " << i;
    // An edge <= 9 touches at most 3 blocks of 4 per axis: within the read budget, so exact.
    EXPECT_EQ(got, brute(v, 0, block_aligned(box, 4))) << "region " << i;
  }
}

TEST(LazyMetadata, ConcurrentQueriesAgreeWithBruteForce) {
  const glm::u64vec3 extent(40, 40, 40);
  const DenseVolume v = random_volume(extent, VoxelType::u8, 2, 8);
  PyramidSourceOptions o;
  o.metadata_block = 4;
  o.eager_scan_voxels = 0;
  o.lazy_query_blocks = 27;
  o.lazy_cache_entries = 256;  // evictions race with lookups and inserts
  o.threads = 1;
  const auto lazy = make_dense_pyramid_source(v, BrickLayout{glm::uvec3(8), 1}, "lazy", o);
  std::atomic<int> wrong{0};
  std::vector<std::thread> pool;
  for (std::uint32_t t = 0; t < 4; ++t) {
    pool.emplace_back([&, t] {
      std::mt19937 rng(100 + t);
      for (int i = 0; i < 150; ++i) {
        const std::uint32_t c = std::uint32_t(rng() % 2);
        const Box3 box = random_box(rng, extent, 9);
        if (lazy->region_meta(c, box) != brute(v, c, block_aligned(box, 4))) ++wrong;
      }
    });
  }
  for (std::thread& th : pool) th.join();
  EXPECT_EQ(wrong.load(), 0);
}

TEST(LazyMetadata, RangesFromDataUseTheCoarsestStoredLevelThatFits) {
  const glm::u64vec3 extent(64, 64, 64);
  const DenseVolume v = random_volume(extent, VoxelType::f32, 1, 4);
  VolumeDesc d = v.desc();
  const Box3 whole{glm::i64vec3(0), glm::i64vec3(extent)};
  auto shared = std::make_shared<const DenseVolume>(v);
  LevelBoxReader level0 = [shared, whole](std::uint32_t c, const Box3& box,
                                          std::span<std::byte> out) {
    copy_box_clamped(shared->channel_bytes(c), whole, out, box, 4);
  };
  // A stored level 1 whose voxels are a ramp 2..9.5 (not the average of level 0, which a
  // stored level need not be): the range must come from it, not from level 0.
  LevelBoxReader level1 = [](std::uint32_t, const Box3& box, std::span<std::byte> out) {
    std::size_t i = 0;
    for (std::int64_t z = box.lo.z; z < box.hi.z; ++z) {
      for (std::int64_t y = box.lo.y; y < box.hi.y; ++y) {
        for (std::int64_t x = box.lo.x; x < box.hi.x; ++x, ++i) {
          const float f = 2.0f + 0.25f * float(z % 31);
          std::memcpy(out.data() + 4 * i, &f, 4);
        }
      }
    }
  };
  PyramidSourceOptions o;
  o.ranges_from_data = true;
  o.eager_scan_voxels = 32 * 32 * 32;  // level 1 fits, level 0 does not
  o.threads = 1;
  const BrickLayout layout{glm::uvec3(8), 1};
  const PyramidSource src(d, layout, {level0, level1}, "stored", o);
  EXPECT_TRUE(src.lazy_metadata());
  EXPECT_EQ(src.volume().range(0), (ValueRange{2.0, 9.5}));
  // Without a stored level that fits: the type's default range, and no voxel read at all.
  std::atomic<int> reads{0};
  LevelBoxReader counting = [&](std::uint32_t c, const Box3& box, std::span<std::byte> out) {
    ++reads;
    level0(c, box, out);
  };
  o.eager_scan_voxels = 1000;
  const PyramidSource bare(d, layout, {counting}, "bare", o);
  EXPECT_EQ(bare.volume().range(0), default_range(VoxelType::f32));
  EXPECT_EQ(reads.load(), 0);
}

TEST(LazyMetadata, BadOptionsAreNamed) {
  const DenseVolume v = random_volume(glm::u64vec3(8), VoxelType::u8, 1, 1);
  PyramidSourceOptions o;
  o.lazy_query_blocks = 0;
  EXPECT_RESOCT_ERROR(make_dense_pyramid_source(v, BrickLayout{}, "x", o),
                      ErrorCode::invalid_argument, "lazy_query_blocks");
  o = {};
  o.lazy_cache_entries = 0;
  EXPECT_RESOCT_ERROR(make_dense_pyramid_source(v, BrickLayout{}, "x", o),
                      ErrorCode::invalid_argument, "lazy_cache_entries");
}

/// An in-memory zarr store that counts every get and get_range.
class CountingMemoryStore final : public ByteStore {
 public:
  std::map<std::string, std::vector<std::byte>> objects;
  mutable std::atomic<std::uint64_t> gets{0};

  void put(const std::string& key, const std::string& text) {
    const auto* p = reinterpret_cast<const std::byte*>(text.data());
    objects[key] = std::vector<std::byte>(p, p + text.size());
  }
  std::optional<std::vector<std::byte>> get(std::string_view key,
                                            std::uint64_t max_bytes) const override {
    ++gets;
    const auto it = objects.find(std::string(key));
    if (it == objects.end()) return std::nullopt;
    if (it->second.size() > max_bytes) throw Error(ErrorCode::out_of_range, "too large");
    return it->second;
  }
  std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                   std::uint64_t size) const override {
    ++gets;
    const std::vector<std::byte>& b = objects.at(std::string(key));
    return {b.begin() + std::ptrdiff_t(offset), b.begin() + std::ptrdiff_t(offset + size)};
  }
  std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                             std::uint64_t offset,
                                                             std::uint64_t size) const override {
    if (!objects.contains(std::string(key))) return std::nullopt;
    return get_range(key, offset, size);
  }
  std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const override {
    const auto it = objects.find(std::string(key));
    if (it == objects.end()) return std::nullopt;
    return ObjectTail{get_range(key, it->second.size() - size, size), it->second.size()};
  }
  std::string location(std::string_view key) const override {
    return "mem://huge/" + std::string(key);
  }
};

TEST(LazyMetadata, HugeDeclaredZarrOpensFromMetadataAlone) {
  // 16384 x 8192 x 8192 u16 voxels (2^40) in 64^3 chunks: one chunk written, the rest missing
  // (fill value 7). Eager opening would read 2^40 voxels.
  auto store = std::make_shared<CountingMemoryStore>();
  store->put(".zarray",
             R"({"zarr_format": 2, "shape": [8192, 8192, 16384], "chunks": [64, 64, 64],
                 "dtype": "<u2", "compressor": null, "fill_value": 7, "order": "C",
                 "filters": null})");
  std::vector<std::uint16_t> chunk(64 * 64 * 64);
  for (std::size_t i = 0; i < chunk.size(); ++i) chunk[i] = std::uint16_t(100 + i % 1000);
  const auto* cp = reinterpret_cast<const std::byte*>(chunk.data());
  store->objects["0.0.0"] = std::vector<std::byte>(cp, cp + chunk.size() * 2);

  OmeZarrOptions o;
  o.pyramid.threads = 1;
  const auto src = open_ome_zarr(store, BrickLayout{glm::uvec3(32), 1}, o);
  const std::uint64_t open_gets = store->gets.load();
  EXPECT_LE(open_gets, 4u) << "open may read metadata objects only";
  ASSERT_TRUE(src->lazy_metadata());
  EXPECT_EQ(src->volume().extent, glm::u64vec3(16384, 8192, 8192));
  EXPECT_EQ(src->volume().range(0), default_range(VoxelType::u16)) << "no window, no scan";

  // The whole volume: answered "unknown" without reading anything.
  const Box3 all{glm::i64vec3(0), glm::i64vec3(src->volume().extent)};
  const RegionMeta whole = src->region_meta(0, all);
  EXPECT_EQ(whole.min, 0.0);
  EXPECT_EQ(whole.max, 65535.0);
  EXPECT_EQ(store->gets.load(), open_gets);
  // A brick-sized region in a missing chunk: exactly the fill value, from one chunk get.
  const RegionMeta far = src->region_meta(0, Box3{{8000, 4000, 4000}, {8034, 4034, 4034}});
  EXPECT_EQ(far.min, 7.0);
  EXPECT_EQ(far.max, 7.0);
  EXPECT_EQ(far.occupancy, occupancy_bit(7.0, src->volume().range(0)));
  EXPECT_LE(store->gets.load() - open_gets, 8u);
  // Inside the written chunk: the brute-force summary of the chunk's voxels there.
  const Box3 near{{3, 5, 7}, {40, 30, 20}};
  RegionMeta want;
  // The touched metadata blocks of 16 voxels: [0, 48) x [0, 32) x [0, 32).
  for (std::int64_t z = 0; z < 32; ++z) {
    for (std::int64_t y = 0; y < 32; ++y) {
      for (std::int64_t x = 0; x < 48; ++x) {
        const double val = chunk[std::size_t((z * 64 + y) * 64 + x)];
        want.merge(RegionMeta{val, val, occupancy_bit(val, src->volume().range(0))});
      }
    }
  }
  EXPECT_EQ(src->region_meta(0, near), want);
  // Bricks still read: a level-0 brick of the written chunk.
  std::vector<std::byte> brick(src->hierarchy().layout().padded_voxels() * 2);
  src->read_brick(BrickKey(0, 0, glm::uvec3(0)), brick);
  std::uint16_t first;
  std::memcpy(&first, brick.data(), 2);
  EXPECT_EQ(first, chunk[0]) << "halo voxel clamps to voxel (0,0,0)";
}

}  // namespace
