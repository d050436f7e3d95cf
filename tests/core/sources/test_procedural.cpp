#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/sources/brick_error.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/expect_error.hpp"
#include "support/reference_levels.hpp"

using namespace resoct;

namespace {

const char* const kNames[] = {"tubes", "noisefloor", "turbulence", "mandelbulb",
                              "cells", "constant",   "ramp",       "sphere"};

// A small spec of every dataset; cells needs at least 16 channels.
std::string small_spec(const std::string& name, const std::string& size) {
  return "procedural:" + name + ":" + size + (name == "cells" ? ":16" : "");
}

std::vector<double> read_level(const ProceduralSource& src, std::uint32_t level,
                               std::uint32_t channel) {
  const LevelInfo& li = src.hierarchy().level(level);
  const Box3 box{glm::i64vec3(0), glm::i64vec3(li.extent)};
  const VoxelType t = src.volume().type;
  std::vector<std::byte> bytes(std::size_t(box.volume()) * voxel_size(t));
  src.read_region(level, channel, box, bytes);
  std::vector<double> v(std::size_t(box.volume()));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = test::voxel_as_double(bytes.data(), i, t);
  return v;
}

std::vector<std::byte> brick(const BrickSource& src, BrickKey k) {
  std::vector<std::byte> b(src.hierarchy().layout().padded_voxels() *
                           voxel_size(src.volume().type));
  src.read_brick(k, b);
  return b;
}

// The bound of procedural_source.hpp, recomputed here from its definition.
double documented_bound(const ProceduralSource& src, std::uint32_t level, std::uint32_t channel,
                        std::uint32_t s) {
  const glm::uvec3 f = src.hierarchy().level(level).factor_log2;
  if (f.x <= s && f.y <= s && f.z <= s) return 0.0;
  const VoxelType t = src.volume().type;
  const double scale = t == VoxelType::u8 ? 255.0 : t == VoxelType::u16 ? 65535.0 : 1.0;
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double n = std::pow(2.0, double(f[a] > s ? f[a] - s : 0));
    d2 += (n - 1.0) * (n - 1.0) / 4.0;
  }
  const double q = t == VoxelType::f32 ? 1e-6 * (level + 2) : 0.5 * (level + 2);
  return src.field().lipschitz(channel) * scale * std::sqrt(d2) + q;
}

// procedural_source.hpp's table of observed coarse-level errors, in stored units, for
// samples_log2 = 1 and 2.
double observed_error_limit(const std::string& name, std::uint32_t s) {
  const bool fine = s >= 2;
  if (name == "tubes") return fine ? 24.0 : 80.0;
  if (name == "mandelbulb") return fine ? 24.0 : 64.0;
  if (name == "noisefloor") return fine ? 6.0 : 24.0;
  if (name == "turbulence") return fine ? 6.0 : 16.0;
  if (name == "cells") return fine ? 3000.0 : 12000.0;
  if (name == "sphere") return fine ? 0.02 : 0.05;
  return 1e-6;  // constant, ramp
}

}  // namespace

TEST(ProceduralSpec, DefaultsAndExplicitFields) {
  ProceduralSpec s = parse_procedural_spec("procedural:tubes");
  EXPECT_EQ(s.name, "tubes");
  EXPECT_EQ(s.extent, glm::u64vec3(256));
  EXPECT_EQ(s.channels, 1u);
  EXPECT_EQ(s.type, VoxelType::u8);
  s = parse_procedural_spec("procedural:cells");
  EXPECT_EQ(s.extent, glm::u64vec3(1024, 1024, 40));
  EXPECT_EQ(s.channels, 16u);
  EXPECT_EQ(s.type, VoxelType::u16);
  s = parse_procedural_spec("procedural:cells:100x90x12:32");
  EXPECT_EQ(s.extent, glm::u64vec3(100, 90, 12));
  EXPECT_EQ(s.channels, 32u);
  EXPECT_EQ(parse_procedural_spec("procedural:ramp:7x8x9:3").type, VoxelType::f32);
  EXPECT_EQ(parse_procedural_spec("procedural:sphere").type, VoxelType::f32);
  EXPECT_EQ(parse_procedural_spec("procedural:constant").type, VoxelType::f32);
  EXPECT_EQ(ProceduralSource("procedural:tubes:64x32x16").name(), "procedural:tubes:64x32x16");
  EXPECT_EQ(make_procedural_source("procedural:ramp:8x8x8:2")->name(), "procedural:ramp:8x8x8:2");
}

TEST(ProceduralSpec, RejectsMalformedSpecsNamingTheParameter) {
  const ErrorCode bad = ErrorCode::invalid_argument;
  EXPECT_RESOCT_ERROR(parse_procedural_spec("tubes"), bad, "procedural:");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubez"), bad, "unknown dataset 'tubez'");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:"), bad, "unknown dataset");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:0x4x4"), bad, "spec");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:4x4"), bad, "not WxHxD");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:4xax4"), bad, "spec");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:4x4x-4"), bad, "spec");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:4x4x4:0"), bad, "channels");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:4x4x4:17"), bad, "channels");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:cells:64x64x8:8"), bad, "16..32");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:cells:64x64x8:33"), bad, "channels");
  EXPECT_RESOCT_ERROR(parse_procedural_spec("procedural:tubes:4x4x4:1:x"), bad, "spec");
  EXPECT_RESOCT_ERROR(ProceduralSource("procedural:tubes:8x8x8", BrickLayout{glm::uvec3(2), 1}),
                      bad, "brick_size");
  EXPECT_RESOCT_ERROR(ProceduralSource("procedural:tubes:8x8x8", BrickLayout{}, 4), bad,
                      "samples_log2");
  const ProceduralSource src("procedural:tubes:16x16x16", BrickLayout{glm::uvec3(8), 1});
  std::vector<std::byte> small(10);
  EXPECT_RESOCT_ERROR(src.read_brick(BrickKey(0, 0, {0, 0, 0}), small), bad, "out");
  std::vector<std::byte> ok(1000);
  EXPECT_RESOCT_ERROR(src.read_brick(BrickKey(0, 1, {0, 0, 0}), ok), ErrorCode::out_of_range,
                      "channel 1");
  EXPECT_RESOCT_ERROR(src.region_meta(3, Box3{{0, 0, 0}, {1, 1, 1}}), ErrorCode::out_of_range,
                      "channel");
  std::vector<std::byte> one(1);
  EXPECT_RESOCT_ERROR(src.read_region(9, 0, Box3{{0, 0, 0}, {1, 1, 1}}, one),
                      ErrorCode::out_of_range, "level");
  EXPECT_RESOCT_ERROR(src.read_region(0, 0, Box3{{0, 0, 0}, {17, 1, 1}}, one), bad, "box");
  EXPECT_RESOCT_ERROR(src.read_region(0, 0, Box3{{0, 0, 0}, {2, 1, 1}}, one), bad, "out");
  EXPECT_RESOCT_ERROR(src.coarse_error_bound(0, 1), ErrorCode::out_of_range, "channel");
}

TEST(Procedural, AnalyticDatasetsHoldTheirDocumentedValues) {
  const ProceduralSource ramp("procedural:ramp:40x24x12:3", BrickLayout{glm::uvec3(8), 2});
  const ProceduralSource sphere("procedural:sphere:40x24x12", BrickLayout{glm::uvec3(8), 2});
  const ProceduralSource constant("procedural:constant:40x24x12", BrickLayout{glm::uvec3(8), 2});
  const glm::i64vec3 e(40, 24, 12);
  for (std::uint32_t c = 0; c < 3; ++c) {
    const std::vector<double> v = read_level(ramp, 0, c);
    std::size_t i = 0;
    for (std::int64_t z = 0; z < e.z; ++z)
      for (std::int64_t y = 0; y < e.y; ++y)
        for (std::int64_t x = 0; x < e.x; ++x, ++i) {
          const glm::i64vec3 p(x, y, z);
          ASSERT_EQ(v[i], double(float((double(p[int(c)]) + 0.5) / double(e[int(c)]))));
        }
  }
  const std::vector<double> s = read_level(sphere, 0, 0);
  const std::vector<double> k = read_level(constant, 0, 0);
  std::size_t i = 0;
  for (std::int64_t z = 0; z < e.z; ++z)
    for (std::int64_t y = 0; y < e.y; ++y)
      for (std::int64_t x = 0; x < e.x; ++x, ++i) {
        const double dx = double(x) + 0.5 - 20.0, dy = double(y) + 0.5 - 12.0,
                     dz = double(z) + 0.5 - 6.0;
        const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
        ASSERT_NEAR(s[i], std::max(0.0, 1.0 - r / 6.0), 1e-6);
        ASSERT_EQ(k[i], 0.5);
      }
  // Ramp coarse levels stay linear: level-1 voxel 3 averages level-0 voxels 6 and 7.
  const std::vector<double> l1 = read_level(ramp, 1, 0);
  EXPECT_NEAR(l1[3], (6.5 + 7.5) / 2.0 / 40.0, 1e-7);
}

TEST(Procedural, BricksAreClampedViewsOfTheLevels) {
  for (const char* name : kNames) {
    const ProceduralSource src(small_spec(name, "21x19x10"), BrickLayout{glm::uvec3(4), 2});
    const BrickHierarchy& h = src.hierarchy();
    const VoxelType t = src.volume().type;
    for (std::uint32_t c : {0u, src.volume().channels - 1}) {
      for (std::uint32_t l = 0; l < h.level_count(); ++l) {
        const LevelInfo& li = h.level(l);
        const std::vector<double> lv = read_level(src, l, c);
        for (std::uint32_t b = 0; b < li.brick_count; b += 3) {
          const glm::uvec3 bc(b % li.bricks.x, (b / li.bricks.x) % li.bricks.y,
                              b / (li.bricks.x * li.bricks.y));
          const std::vector<std::byte> buf = brick(src, BrickKey(l, c, bc));
          const Box3 p = h.padded_box(l, bc);
          std::size_t i = 0;
          for (std::int64_t z = p.lo.z; z < p.hi.z; ++z)
            for (std::int64_t y = p.lo.y; y < p.hi.y; ++y)
              for (std::int64_t x = p.lo.x; x < p.hi.x; ++x, ++i) {
                const std::int64_t gx = test::clamp_index(x, li.extent.x);
                const std::int64_t gy = test::clamp_index(y, li.extent.y);
                const std::int64_t gz = test::clamp_index(z, li.extent.z);
                ASSERT_EQ(test::voxel_as_double(buf.data(), i, t),
                          lv[std::size_t((gz * li.extent.y + gy) * li.extent.x + gx)])
                    << name << " level " << l << " brick " << b;
              }
        }
      }
    }
  }
}

TEST(Procedural, CoarseLevelsStayWithinTheDocumentedErrorBound) {
  for (std::uint32_t s : {1u, 2u}) {
    for (const char* name : kNames) {
      const std::string spec =
          small_spec(name, std::string(name) == "cells" ? "64x64x16" : "48x48x48");
      const ProceduralSource src(spec, BrickLayout{glm::uvec3(4), 0}, s);
      const BrickHierarchy& h = src.hierarchy();
      ASSERT_GE(h.level_count(), 5u);
      std::vector<std::uint32_t> channels{0};
      if (src.volume().channels > 1) channels.push_back(src.volume().channels - 1);
      for (std::uint32_t c : channels) {
        const std::vector<test::RefLevel> ref =
            test::reference_levels(h, read_level(src, 0, c), src.volume().type);
        for (std::uint32_t l = 1; l < h.level_count(); ++l) {
          const std::vector<double> got = read_level(src, l, c);
          double err = 0.0;
          for (std::size_t i = 0; i < got.size(); ++i) {
            err = std::max(err, std::abs(got[i] - ref[l].v[i]));
          }
          const double bound = documented_bound(src, l, c, s);
          EXPECT_EQ(src.coarse_error_bound(l, c), bound);
          std::cout << "s " << s << " " << name << " ch " << c << " level " << l << " f "
                    << h.level(l).factor_log2.x << "," << h.level(l).factor_log2.y << ","
                    << h.level(l).factor_log2.z << " max error " << err << " bound " << bound
                    << "\n";
          const bool exact = glm::all(glm::lessThanEqual(h.level(l).factor_log2, glm::uvec3(s)));
          EXPECT_EQ(src.exact_level(l), exact);
          if (exact) {
            EXPECT_EQ(err, 0.0) << name << " level " << l;
          } else {
            EXPECT_LE(err, bound) << name << " level " << l;
            // The observed (not proven) errors documented in procedural_source.hpp.
            EXPECT_LE(err, observed_error_limit(name, s)) << name << " level " << l;
          }
        }
      }
    }
  }
}

TEST(Procedural, RegionMetaIsConservativeForLevel0Voxels) {
  std::mt19937 rng(2024);
  for (const char* name : kNames) {
    const std::string spec =
        small_spec(name, std::string(name) == "cells" ? "64x56x12" : "40x36x30");
    const ProceduralSource src(spec, BrickLayout{glm::uvec3(8), 1});
    const glm::i64vec3 e(src.volume().extent);
    std::vector<std::uint32_t> channels{0};
    if (src.volume().channels > 1) channels.insert(channels.end(), {1, 2, 3});
    for (std::uint32_t c : channels) {
      const std::vector<double> l0 = read_level(src, 0, c);
      const ValueRange r = src.volume().range(c);
      for (int trial = 0; trial < 150; ++trial) {
        Box3 b;
        for (int a = 0; a < 3; ++a) {
          const std::int64_t len =
              1 + std::int64_t(rng() % std::uint64_t(trial % 3 == 0 ? e[a] : 9));
          b.lo[a] = std::int64_t(rng() % std::uint64_t(e[a]));
          b.hi[a] = std::min(e[a] + 2, b.lo[a] + len);
        }
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        std::uint32_t occ = 0;
        for (std::int64_t z = b.lo.z; z < std::min(b.hi.z, e.z); ++z)
          for (std::int64_t y = b.lo.y; y < std::min(b.hi.y, e.y); ++y)
            for (std::int64_t x = b.lo.x; x < std::min(b.hi.x, e.x); ++x) {
              const double v = l0[std::size_t((z * e.y + y) * e.x + x)];
              lo = std::min(lo, v);
              hi = std::max(hi, v);
              occ |= occupancy_bit(v, r);
            }
        const RegionMeta m = src.region_meta(c, b);
        ASSERT_LE(m.min, lo) << name << " channel " << c << " trial " << trial;
        ASSERT_GE(m.max, hi) << name << " channel " << c << " trial " << trial;
        ASSERT_EQ(m.occupancy & occ, occ) << name << " channel " << c << " trial " << trial;
      }
    }
    EXPECT_EQ(src.region_meta(0, Box3{{-5, 0, 0}, {0, 4, 4}}), RegionMeta{});
  }
}

TEST(Procedural, TubesRegionMetaProvesMostBlocksEmpty) {
  const ProceduralSource src("procedural:tubes:128x128x128", BrickLayout{glm::uvec3(16), 1});
  const std::vector<double> l0 = read_level(src, 0, 0);
  int blocks = 0, reported_empty = 0, truly_empty = 0;
  for (std::int64_t bz = 0; bz < 128; bz += 16)
    for (std::int64_t by = 0; by < 128; by += 16)
      for (std::int64_t bx = 0; bx < 128; bx += 16) {
        const Box3 b{{bx, by, bz}, {bx + 16, by + 16, bz + 16}};
        double hi = 0.0;
        for (std::int64_t z = b.lo.z; z < b.hi.z; ++z)
          for (std::int64_t y = b.lo.y; y < b.hi.y; ++y)
            for (std::int64_t x = b.lo.x; x < b.hi.x; ++x)
              hi = std::max(hi, l0[std::size_t((z * 128 + y) * 128 + x)]);
        const RegionMeta m = src.region_meta(0, b);
        ++blocks;
        truly_empty += hi == 0.0;
        if (m.max == 0.0) {
          ++reported_empty;
          EXPECT_EQ(hi, 0.0);
          EXPECT_EQ(m.occupancy, 1u);  // only the zero bin
        }
      }
  std::cout << "tubes 128^3: " << reported_empty << " of " << blocks << " blocks reported empty, "
            << truly_empty << " truly empty\n";
  // Mostly empty data, and the bounds see most of that emptiness.
  EXPECT_GE(truly_empty * 10, blocks * 6);
  EXPECT_GE(reported_empty * 10, truly_empty * 8);
  // The whole volume is not empty.
  EXPECT_GT(src.region_meta(0, Box3{{0, 0, 0}, {128, 128, 128}}).max, 0.0);
}

TEST(Procedural, NoiseFloorIsTransparentButNeverEmpty) {
  const ProceduralSource src("procedural:noisefloor:48x48x48");
  const std::vector<double> l0 = read_level(src, 0, 0);
  const auto [mn, mx] = std::minmax_element(l0.begin(), l0.end());
  EXPECT_GE(*mn, 7.0);    // floor 0.03 * 255
  EXPECT_LE(*mn, 13.0);   // and low
  EXPECT_GT(*mx, 100.0);  // blobs
  for (std::uint64_t i = 0; i < src.hierarchy().bricks_per_channel(); ++i) {
    EXPECT_FALSE(src.brick_meta(src.hierarchy().key_from_linear(0, i)).all_zero());
  }
  EXPECT_GE(src.region_meta(0, Box3{{0, 0, 0}, {48, 48, 48}}).min, 7.0);
}

TEST(Procedural, HugeVolumesAreVirtual) {
  for (const char* name : kNames) {
    const std::string spec = "procedural:" + std::string(name) + ":65536x65536x65536" +
                             (std::string(name) == "cells" ? ":16" : "");
    const ProceduralSource src(spec);
    const BrickHierarchy& h = src.hierarchy();
    EXPECT_EQ(h.level(0).bricks, glm::uvec3(2048));
    const std::uint32_t top = h.level_count() - 1;
    EXPECT_EQ(h.level(top).brick_count, 1u);
    const std::uint32_t c = src.volume().channels - 1;
    // The bricks around the centre at level 0, and the single coarsest brick.
    for (BrickKey k : {BrickKey(0, c, {1024, 1024, 1024}), BrickKey(0, 0, {1023, 1000, 30}),
                       BrickKey(top, c, {0, 0, 0})}) {
      const std::vector<std::byte> b = brick(src, k);
      const BrickMeta m = scan_brick(b, src.volume().type);
      const ValueRange r = src.volume().range(k.channel());
      EXPECT_GE(m.min, r.lo) << name;
      EXPECT_LE(m.max, r.hi) << name;
    }
    const RegionMeta whole = src.region_meta(c, Box3{{0, 0, 0}, glm::i64vec3(65536)});
    EXPECT_LE(whole.min, whole.max) << name;
    EXPECT_NE(whole.occupancy, 0u) << name;
  }
  // Values that can be checked analytically at this size.
  const ProceduralSource ramp("procedural:ramp:65536x65536x65536");
  const std::vector<std::byte> b = brick(ramp, BrickKey(0, 0, {2047, 0, 0}));
  // Halo 1: padded x index 32 is level-0 voxel 65535, index 33 clamps to it.
  EXPECT_EQ(test::voxel_as_double(b.data(), 32, VoxelType::f32), double(float(65535.5 / 65536.0)));
  EXPECT_EQ(test::voxel_as_double(b.data(), 33, VoxelType::f32), double(float(65535.5 / 65536.0)));
  const ProceduralSource sphere("procedural:sphere:65536x65536x65536");
  const std::uint32_t top = sphere.hierarchy().level_count() - 1;
  const std::vector<std::byte> t = brick(sphere, BrickKey(top, 0, {0, 0, 0}));
  // Coarsest voxel (16,16,16) covers [32768, 34816)^3, a cube of side 2048 with a corner at the
  // centre: the mean distance from a unit cube's corner is 0.9607, so the mean of 1 - r / R is
  // 1 - 0.9607 * 2048 / 32768.
  const std::size_t centre = (17u * 34u + 17u) * 34u + 17u;
  EXPECT_NEAR(test::voxel_as_double(t.data(), centre, VoxelType::f32),
              1.0 - 0.9607 * 2048.0 / 32768.0, 0.002);
}

TEST(Procedural, SameSpecGivesSameBytesAndChannelsDiffer) {
  for (const char* name : kNames) {
    const std::string spec = small_spec(name, "40x40x24");
    const ProceduralSource a(spec, BrickLayout{glm::uvec3(8), 1});
    const auto b = make_procedural_source(spec, BrickLayout{glm::uvec3(8), 1});
    const BrickHierarchy& h = a.hierarchy();
    for (std::uint64_t i = 0; i < h.bricks_per_channel(); i += 5) {
      const BrickKey k = h.key_from_linear(a.volume().channels - 1, i);
      EXPECT_EQ(brick(a, k), brick(*b, k)) << name << " brick " << i;
    }
  }
  // Concurrent reads (the loader's pattern) give the same bytes as sequential ones.
  const ProceduralSource tubes("procedural:tubes:96x96x96", BrickLayout{glm::uvec3(16), 1});
  const BrickHierarchy& h = tubes.hierarchy();
  std::vector<std::vector<std::byte>> seq;
  for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i) {
    seq.push_back(brick(tubes, h.key_from_linear(0, i)));
  }
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (std::uint64_t i = std::uint64_t(t); i < h.bricks_per_channel(); i += 4) {
        mismatches[std::size_t(t)] += brick(tubes, h.key_from_linear(0, i)) != seq[i];
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
  // Cells: every channel is a different marker, so no two channels are identical, and markers
  // light only part of the cells that the nuclear channel 0 shows.
  const ProceduralSource cells("procedural:cells:128x128x16:16");
  std::vector<std::vector<double>> ch;
  for (std::uint32_t c = 0; c < 16; ++c) ch.push_back(read_level(cells, 0, c));
  for (std::uint32_t c = 0; c < 16; ++c) {
    EXPECT_GT(*std::max_element(ch[c].begin(), ch[c].end()), 0.0) << "channel " << c;
    for (std::uint32_t d = c + 1; d < 16; ++d) EXPECT_NE(ch[c], ch[d]) << c << " vs " << d;
  }
}

TEST(Procedural, ShortcutsForConstantBricksAgreeWithFullEvaluation) {
  // read_brick and brick_meta skip evaluation where the field is provably constant; compare both
  // with bricks assembled from read_region, which always evaluates.
  for (const char* name : {"tubes", "mandelbulb", "constant", "cells", "noisefloor"}) {
    const std::string spec =
        small_spec(name, std::string(name) == "cells" ? "64x64x12" : "64x64x64");
    const ProceduralSource src(spec, BrickLayout{glm::uvec3(8), 1});
    const BrickHierarchy& h = src.hierarchy();
    const VoxelType t = src.volume().type;
    const std::uint32_t c = src.volume().channels - 1;
    std::uint64_t zero_bricks = 0;
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const LevelInfo& li = h.level(l);
      const std::vector<double> lv = read_level(src, l, c);
      for (std::uint64_t i = 0; i < li.brick_count; ++i) {
        const BrickKey k = h.key_from_linear(c, li.first_brick + i);
        const std::vector<std::byte> buf = brick(src, k);
        const Box3 p = h.padded_box(l, k.brick());
        BrickMeta want;
        std::size_t j = 0;
        for (std::int64_t z = p.lo.z; z < p.hi.z; ++z)
          for (std::int64_t y = p.lo.y; y < p.hi.y; ++y)
            for (std::int64_t x = p.lo.x; x < p.hi.x; ++x, ++j) {
              const double v =
                  lv[std::size_t((test::clamp_index(z, li.extent.z) * std::int64_t(li.extent.y) +
                                  test::clamp_index(y, li.extent.y)) *
                                     std::int64_t(li.extent.x) +
                                 test::clamp_index(x, li.extent.x))];
              ASSERT_EQ(test::voxel_as_double(buf.data(), j, t), v) << name << " brick " << i;
              if (j > 0 && v != want.min) want.constant = false;
              want.min = std::min(want.min, v);
              want.max = std::max(want.max, v);
            }
        const BrickMeta got = src.brick_meta(k);
        EXPECT_EQ(got, want) << name << " level " << l << " brick " << i;
        zero_bricks += got.all_zero();
      }
    }
    if (std::string(name) == "tubes") {
      EXPECT_GT(zero_bricks * 2, h.bricks_per_channel());
    }
    if (std::string(name) == "constant") {
      EXPECT_EQ(zero_bricks, 0u);
    }
  }
}

// ProceduralSource::brick_error_bound (lipschitz_brick_error_bound) is an upper bound on the
// measured down-sampling error of every coarse brick: odd extents (partial footprints, repeated
// border voxels), halo 0 and 1, both sample counts, every dataset with a Lipschitz constant.
// Where the field is smooth (sphere, ramp) the bound must also be near what is measured, so a
// bound made loose by a wrong moment or rounding term fails too.
TEST(Procedural, BrickErrorBoundIsAboveEveryMeasuredError) {
  for (std::uint32_t s : {1u, 2u}) {
    for (std::uint32_t halo : {0u, 1u}) {
      for (const char* name : kNames) {
        const std::string n = name;
        const std::string spec = small_spec(n, n == "cells" ? "70x52x11" : "37x29x23");
        const ProceduralSource src(spec, BrickLayout{glm::uvec3(4), halo}, s);
        const BrickHierarchy& h = src.hierarchy();
        ASSERT_GE(h.level_count(), 4u);
        std::vector<std::uint32_t> channels{0};
        if (src.volume().channels > 1) channels.push_back(src.volume().channels - 1);
        for (std::uint32_t c : channels) {
          const bool bounded = std::isfinite(src.field().lipschitz(c));
          double worst_ratio = 0.0;
          for (std::uint32_t l = 1; l < h.level_count(); ++l) {
            const glm::uvec3 nb = h.level(l).bricks;
            for (std::uint32_t z = 0; z < nb.z; ++z) {
              for (std::uint32_t y = 0; y < nb.y; ++y) {
                for (std::uint32_t x = 0; x < nb.x; ++x) {
                  const BrickKey key(l, c, {x, y, z});
                  const double bound = src.brick_error_bound(key);
                  if (!bounded) {
                    EXPECT_EQ(bound, 1.0) << name;
                    continue;
                  }
                  const std::vector<std::byte> b = brick(src, key);
                  // Measured in full: no metadata or analytic shortcut, no budget.
                  const double measured =
                      measure_brick_error(src, key, b, std::uint64_t(1) << 40, 1.0);
                  EXPECT_LE(measured, bound)
                      << spec << " s " << s << " halo " << halo << " level " << l << " brick " << x
                      << "," << y << "," << z << " channel " << c;
                  EXPECT_GE(bound, 0.0);
                  EXPECT_LE(bound, 1.0);
                  // What the source answers never exceeds the bound and is what it measures.
                  EXPECT_LE(src.brick_error(key, b), bound);
                  if (bound > 0.0) worst_ratio = std::max(worst_ratio, measured / bound);
                }
              }
            }
          }
          std::cout << spec << " s " << s << " halo " << halo << " channel " << c
                    << ": largest measured / bound " << worst_ratio << "\n";
          // Smooth fields: measured 0.92 (sphere) and 0.47-0.55 (ramp) of the bound at worst.
          if (n == "sphere") EXPECT_GT(worst_ratio, 0.8) << spec;
          if (n == "ramp") EXPECT_GT(worst_ratio, 0.4) << spec;
        }
      }
    }
  }
}

// Bricks too large to measure get the analytic bound, far tighter than the metadata spread the
// other sources fall back to there, and at no cost of field evaluations.
TEST(Procedural, BricksTooLargeToMeasureGetTheAnalyticBound) {
  const ProceduralSource src("procedural:sphere:4096x4096x4096");
  const BrickHierarchy& h = src.hierarchy();
  const std::uint32_t l = 5;  // 32³ bricks of factor 32: 2^30 level-0 voxels each
  ASSERT_LT(l, h.level_count());
  const BrickKey key(l, 0, {1, 1, 1});
  ASSERT_GT(std::uint64_t(h.level0_box(l, key.brick()).volume()), kBrickErrorMeasuredVoxels);
  const std::vector<std::byte> b = brick(src, key);
  const double bound = src.brick_error_bound(key);
  EXPECT_GT(bound, 0.0);
  EXPECT_LT(bound, 0.05);
  EXPECT_EQ(src.brick_error(key, b), bound);
  // What the default (metadata spread) gives the same brick: the sphere's value range over it.
  EXPECT_GT(measure_brick_error(src, key, b), 4.0 * bound);
  EXPECT_RESOCT_ERROR(src.brick_error_bound(BrickKey(h.level_count(), 0, {0, 0, 0})),
                      ErrorCode::out_of_range, "key");
}
