// OME-Zarr images written by the reference implementation (zarr-python + numcodecs, generated
// by tests/data/make_ome_zarr.py at test time) against the same numpy arrays written as raw:
// every compressor x dtype x chunking x axis subset, multiscales with stored and computed
// levels, missing chunks (fill_value) and omero windows.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/overview_hints.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "support/brick_compare.hpp"
#include "support/generated_data.hpp"
#include "support/tool_process.hpp"
#include "support/zarr_fixture.hpp"

using namespace resoct;

namespace {

const std::string& data_dir() {
  static const std::string dir = test::python_generated_dir(
      RESOCT_BINARY_DIR "/test-data", "ome-zarr", RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
  return dir;
}

const nlohmann::json& manifest() {
  static const nlohmann::json m = nlohmann::json::parse(test::slurp(data_dir() + "/manifest.json"));
  return m;
}

nlohmann::json find_case(const std::string& name) {
  for (const auto& c : manifest()["cases"]) {
    if (c["name"] == name) return c;
  }
  ADD_FAILURE() << "no case " << name;
  return {};
}

TEST(OmeZarr, EveryCompressorDtypeChunkingAndAxisSubset) {
  ASSERT_FALSE(data_dir().empty());
  const auto& cases = manifest()["cases"];
  ASSERT_GE(cases.size(), 400u);
  std::size_t checked = 0;
  const BrickLayout layout{glm::uvec3(4), 1};
  for (const auto& c : cases) {
    const std::string name = c["name"];
    if (name.starts_with("pyramid") || name.starts_with("fill") || name.starts_with("typed") ||
        name == "omero") {
      continue;
    }
    SCOPED_TRACE(name);
    const std::string axes = c["axes"];
    const auto shape = c["shape"].get<std::vector<std::uint64_t>>();
    const std::uint64_t times = axes.find('t') == std::string::npos ? 1 : shape[axes.find('t')];
    for (std::uint64_t t = 0; t < times; ++t) {
      OmeZarrOptions o;
      o.timepoint = t;
      o.pyramid.threads = 1;
      const auto src = open_ome_zarr(data_dir() + "/" + name + ".zarr", layout, o);
      const VolumeDesc& d = src->volume();
      const std::uint64_t channels =
          axes.find('c') == std::string::npos ? 1 : shape[axes.find('c')];
      ASSERT_EQ(d.channels, channels);
      for (char a : std::string("xyz")) {
        const auto p = axes.find(a);
        const int i = a - 'x';
        EXPECT_EQ(d.extent[i], p == std::string::npos ? 1u : shape[p]);
        EXPECT_EQ(d.spacing[i], p == std::string::npos ? 1.0 : a == 'z' ? 2.0 : 0.5);
      }
      for (std::uint32_t ch = 0; ch < d.channels; ++ch) {
        const auto want = test::fixture_voxels(data_dir(), c, t, ch);
        std::vector<std::byte> got(want.size());
        src->read_level_box(0, ch, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)}, got);
        ASSERT_EQ(std::memcmp(got.data(), want.data(), want.size()), 0) << "t " << t << " c " << ch;
      }
      // Every brick with halo and every coarser level against the brute-force reference.
      test::expect_same_bricks(test::fixture_reference(data_dir(), c, *src, t, layout), *src);
      ++checked;
    }
  }
  EXPECT_GE(checked, 400u);
}

TEST(OmeZarr, StoredLevelsServeTheHierarchyAndMissingOnesAreBuilt) {
  for (const std::string name : {"pyramid_u2", "pyramid_f4"}) {
    SCOPED_TRACE(name);
    const auto c = find_case(name);
    const BrickLayout layout{glm::uvec3(8), 1};
    const auto src = open_ome_zarr(data_dir() + "/" + name + ".zarr", layout);
    ASSERT_EQ(src->hierarchy().level_count(), 4u);
    EXPECT_EQ(src->dataset_of_level(0), 0);
    EXPECT_EQ(src->dataset_of_level(1), 1);
    EXPECT_EQ(src->dataset_of_level(2), 2);
    EXPECT_EQ(src->dataset_of_level(3), -1);
    EXPECT_TRUE(src->stored_level(2));
    EXPECT_FALSE(src->stored_level(3));
    // The file's levels were written with resoct's rule, so stored and computed levels alike
    // equal whole-level downsampling of level 0.
    test::expect_same_bricks(test::fixture_reference(data_dir(), c, *src, 0, layout), *src);
    EXPECT_GT(src->chunk_cache_stats().hits, 0u);
  }
}

TEST(OmeZarr, MissingChunksReadAsFillValue) {
  for (const std::string name : {"fill_u1", "fill_f4"}) {
    SCOPED_TRACE(name);
    const auto c = find_case(name);
    const std::string dir = data_dir() + "/" + name + ".zarr";
    // The far corner chunk was never written (the assertion keeps the test meaningful).
    EXPECT_FALSE(std::filesystem::exists(dir + "/0/2/3/3"));
    EXPECT_TRUE(std::filesystem::exists(dir + "/0/0/0/0"));
    const auto src = open_ome_zarr(dir, BrickLayout{glm::uvec3(4), 1});
    const auto want = test::fixture_voxels(data_dir(), c, 0, 0);
    std::vector<std::byte> got(want.size());
    src->read_level_box(0, 0, Box3{glm::i64vec3(0), glm::i64vec3(src->volume().extent)}, got);
    ASSERT_EQ(std::memcmp(got.data(), want.data(), want.size()), 0);
    const double fill = c["fill"];
    float last;  // the last voxel lies in an unwritten chunk
    if (name == "fill_f4") {
      std::memcpy(&last, got.data() + got.size() - 4, 4);
      EXPECT_EQ(double(last), fill);
    } else {
      EXPECT_EQ(double(std::uint8_t(got.back())), fill);
    }
  }
}

/// The file values of one (t, c) of a case as doubles, x fastest (any dtype of the raw dump).
std::vector<double> expected_values(const nlohmann::json& c, std::uint64_t channel) {
  const std::string dtype = std::string(c["dtype"]).substr(1);
  const std::size_t vs = std::size_t(dtype[1] - '0');
  const auto bytes = test::fixture_values(data_dir(), c, 0, channel);  // little-endian, vs each
  std::vector<double> out;
  for (std::size_t i = 0; i + vs <= bytes.size(); i += vs) {
    auto get = [&](auto v) {
      std::memcpy(&v, bytes.data() + i, sizeof v);
      return double(v);
    };
    if (dtype == "i1") out.push_back(get(std::int8_t()));
    if (dtype == "i2") out.push_back(get(std::int16_t()));
    if (dtype == "i4") out.push_back(get(std::int32_t()));
    if (dtype == "u4") out.push_back(get(std::uint32_t()));
    if (dtype == "f8") out.push_back(get(double()));
  }
  return out;
}

// int8 and int16 are kept exactly as u8 / u16 plus 128 / 32768; int32, uint32 and float64 as
// f32 (rounded to nearest, as a C++ float conversion does). Values, missing-chunk fill and omero
// window come back in the file's units.
TEST(OmeZarr, SignedAndWideDtypesKeepTheirValuesThroughTheMapping) {
  ASSERT_FALSE(data_dir().empty());
  std::size_t checked = 0;
  const BrickLayout layout{glm::uvec3(4), 1};
  for (const auto& c : manifest()["cases"]) {
    const std::string name = c["name"];
    if (!name.starts_with("typed")) continue;
    SCOPED_TRACE(name);
    const std::string dtype = std::string(c["dtype"]).substr(1);
    const auto src = open_ome_zarr(data_dir() + "/" + name + ".zarr", layout);
    const VolumeDesc& d = src->volume();
    const DataType want_type = dtype == "i1"   ? DataType::i8
                               : dtype == "i2" ? DataType::i16
                               : dtype == "i4" ? DataType::i32
                               : dtype == "u4" ? DataType::u32
                                               : DataType::f64;
    EXPECT_EQ(d.data_type, want_type);
    EXPECT_EQ(d.type, dtype == "i1"   ? VoxelType::u8
                      : dtype == "i2" ? VoxelType::u16
                                      : VoxelType::f32);
    for (std::uint32_t ch = 0; ch < d.channels; ++ch) {
      const std::vector<double> want = expected_values(c, ch);
      std::vector<std::byte> got(want.size() * voxel_size(d.type));
      src->read_level_box(0, ch, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)}, got);
      for (std::size_t i = 0; i < want.size(); ++i) {
        double v = 0.0;
        if (d.type == VoxelType::u8) v = double(std::uint8_t(got[i])) - 128.0;
        if (d.type == VoxelType::u16) {
          std::uint16_t u;
          std::memcpy(&u, got.data() + 2 * i, 2);
          v = double(u) - 32768.0;
        }
        if (d.type == VoxelType::f32) {
          float f;
          std::memcpy(&f, got.data() + 4 * i, 4);
          v = double(f);
        }
        const double w = d.type == VoxelType::f32 ? double(float(want[i])) : want[i];
        if (!(std::isnan(w) && std::isnan(v))) {
          ASSERT_EQ(v, w) << "c " << ch << " voxel " << i;
        }
      }
      if (name == "typed_fill_i2") {
        EXPECT_EQ(want.back(), -1024.0);  // the last voxel lies in an unwritten chunk
        EXPECT_EQ(d.data_range(0), (ValueRange{-1000.0, 2000.0}));  // the omero window
      } else {
        double lo = 1e300, hi = -1e300;
        for (double w : want) {
          if (std::isnan(w)) continue;
          const double s = d.type == VoxelType::f32 ? double(float(w)) : w;
          lo = std::min(lo, s), hi = std::max(hi, s);
        }
        EXPECT_EQ(d.data_range(ch), (ValueRange{lo, hi}));  // the data's own signed range
      }
    }
    ++checked;
  }
  EXPECT_EQ(checked, 15u);
}

TEST(OmeZarr, OmeroWindowsAreChannelRanges) {
  const auto src = open_ome_zarr(data_dir() + "/omero.zarr", BrickLayout{glm::uvec3(4), 1});
  EXPECT_EQ(src->volume().range(0), (ValueRange{100.0, 4000.0}));
  EXPECT_EQ(src->volume().range(1), (ValueRange{0.0, 65535.0}));
  ASSERT_EQ(src->multiscales().channels.size(), 2u);
  EXPECT_EQ(src->multiscales().channels[0].label, "DAPI");
  EXPECT_EQ(src->multiscales().channels[1].color, "00FF00");
  EXPECT_EQ(src->array(0).compressor, ZarrCompressor::zlib);
  // The finest dataset's translation (c, z, y, x) places the corner of voxel 0 (x, y, z).
  EXPECT_EQ(src->volume().origin, glm::dvec3(3.0, -2.0, 1.5));
}

// overview_hints: OMERO colours and windows become the overview's transfer functions.
TEST(OmeZarr, OmeroColoursAndWindowsAreOverviewHints) {
  const auto src = open_ome_zarr(data_dir() + "/omero.zarr", BrickLayout{glm::uvec3(4), 1});
  const OverviewHints hints = overview_hints(*src);
  ASSERT_EQ(hints.channels.size(), 2u);
  EXPECT_EQ(hints.channels[0].window, (ValueRange{100.0, 4000.0}));
  ASSERT_TRUE(hints.channels[1].colour.has_value());
  EXPECT_EQ(*hints.channels[1].colour, glm::dvec3(0.0, 1.0, 0.0));
  const Scene s = overview_scene(src->volume(), Viewport{64, 48}, hints);
  ASSERT_EQ(s.channels.size(), 2u);
  // The window is the whole range here (the range is the window): the ramp starts at 0.
  EXPECT_EQ(s.channels[0].tf.evaluate(0.0).a, 0.0);
  EXPECT_GT(s.channels[0].tf.evaluate(0.05).a, 0.0);
  EXPECT_EQ(s.channels[1].tf.evaluate(1.0), glm::dvec4(0.0, 1.0, 0.0, 0.5));
  // Sources without display metadata give only the coarse histograms (test_value_histogram.cpp).
  const OverviewHints plain =
      overview_hints(*make_procedural_source("procedural:tubes:16x16x16:2", {}));
  ASSERT_EQ(plain.channels.size(), 2u);
  for (const ChannelDisplayHint& h : plain.channels) {
    EXPECT_FALSE(h.window.has_value());
    EXPECT_FALSE(h.colour.has_value());
    EXPECT_FALSE(h.histogram.empty());
  }
  EXPECT_EQ(parse_hex_colour("#ff8000"), glm::dvec3(1.0, 128.0 / 255.0, 0.0));
  EXPECT_FALSE(parse_hex_colour("12345").has_value());
  EXPECT_FALSE(parse_hex_colour("GG0000").has_value());
}

/// Any ByteStore works (the HTTP store included); this one counts chunk reads.
class CountingStore final : public ByteStore {
 public:
  explicit CountingStore(std::shared_ptr<ByteStore> inner) : inner_(std::move(inner)) {}
  std::optional<std::vector<std::byte>> get(std::string_view key,
                                            std::uint64_t max_bytes) const override {
    if (!key.ends_with(".zarray") && !key.ends_with(".zattrs") && !key.ends_with("zarr.json")) {
      ++chunk_gets;
    }
    return inner_->get(key, max_bytes);
  }
  std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                   std::uint64_t size) const override {
    return inner_->get_range(key, offset, size);
  }
  std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                             std::uint64_t offset,
                                                             std::uint64_t size) const override {
    return inner_->get_range_if_present(key, offset, size);
  }
  std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const override {
    return inner_->get_suffix(key, size);
  }
  std::string location(std::string_view key) const override { return inner_->location(key); }
  mutable std::atomic<std::uint64_t> chunk_gets{0};

 private:
  std::shared_ptr<ByteStore> inner_;
};

TEST(OmeZarr, DecodedChunkCacheServesEveryBrickCutFromAChunk) {
  // A 3x4x3 grid of 4x3x5 (z, y, x) chunks; bricks of 4^3 with halo are cut across them.
  const std::string dir = data_dir() + "/zstd_leu2_small_zyx.zarr";
  const std::uint64_t chunks = 3 * 4 * 3;  // ceil(11/4) * ceil(10/3) * ceil(13/5)
  for (std::uint64_t budget : {std::uint64_t(64) << 20, std::uint64_t(0)}) {
    auto store = std::make_shared<CountingStore>(open_directory_store(dir));
    OmeZarrOptions o;
    o.chunk_cache_bytes = budget;
    o.pyramid.threads = 1;
    const auto src = open_ome_zarr(store, BrickLayout{glm::uvec3(4), 1}, o);
    const std::uint64_t after_open = store->chunk_gets.load();
    std::vector<std::byte> out(src->hierarchy().layout().padded_voxels() * 2);
    for (std::uint64_t i = 0; i < src->hierarchy().level(0).brick_count; ++i) {
      src->read_brick(src->hierarchy().key_from_linear(0, i), out);
    }
    if (budget != 0) {
      // Each chunk is fetched and decoded once, by the open pass; bricks come from the cache.
      EXPECT_EQ(after_open, chunks);
      EXPECT_EQ(store->chunk_gets.load(), chunks);
      EXPECT_GT(src->chunk_cache_stats().hits, 0u);
    } else {
      // Without a cache every brick refetches the chunks under it (halo neighbours included).
      EXPECT_GT(store->chunk_gets.load() - after_open, chunks);
    }
  }
}

TEST(OmeZarr, RangesFromDataWithoutOmero) {
  const auto c = find_case("zstd_lef4_small_zyx");
  const auto src = open_ome_zarr(data_dir() + "/zstd_lef4_small_zyx.zarr");
  const auto v = test::fixture_voxels(data_dir(), c, 0, 0);
  float lo = 1e30f, hi = -1e30f;
  for (std::size_t i = 0; i < v.size(); i += 4) {
    float f;
    std::memcpy(&f, v.data() + i, 4);
    if (f == f) lo = std::min(lo, f), hi = std::max(hi, f);
  }
  EXPECT_EQ(src->volume().range(0), (ValueRange{double(lo), double(hi)}));
}

}  // namespace

TEST(OmeZarr, EveryTimepointOfASeriesOpenedAtTheFirstReadsThatTimepoint) {
  ASSERT_FALSE(data_dir().empty());
  // A series opened at timepoint 0 reports the t extent and opens each other timepoint itself
  // (shared metadata, own chunk cache and region metadata): bricks of every level and region
  // metadata must be those of that timepoint's voxels. A dozen cases keep the test fast.
  const BrickLayout layout{glm::uvec3(4), 1};
  std::size_t series = 0;
  for (const auto& c : manifest()["cases"]) {
    const std::string name = c["name"];
    const std::string axes = c["axes"];
    if (axes.find('t') == std::string::npos || name.starts_with("pyramid") ||
        name.starts_with("fill") || name.starts_with("typed") || name == "omero")
      continue;
    if (++series > 12) break;
    SCOPED_TRACE(name);
    test::expect_series_of_fixture(data_dir(), c, layout);
  }
  EXPECT_GT(series, 0u);
}
