// OME-Zarr 0.5 (Zarr v3) images written from the specifications by tests/data/make_ome_zarr_v3.py
// at test time (numpy + numcodecs, CRC-32C and shard indexes by hand; no code shared with the
// reader) against the same numpy arrays written as raw: every codec x data type x chunk/shard
// layout, nested sharding, transposes, missing shards and empty inner chunks, the same pyramid as
// 0.4 and 0.5, hostile files (each error names the file and offset), and zarrita (an independent
// Zarr v3 reader) reading every fixture it can.

#include <gtest/gtest.h>

#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/formats/zarr_v3.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/io/open_source.hpp"
#include "support/brick_compare.hpp"
#include "support/expect_error.hpp"
#include "support/generated_data.hpp"
#include "support/tool_process.hpp"
#include "support/zarr_fixture.hpp"

using namespace resoct;

namespace {

const std::string& data_dir() {
  static const std::string dir =
      test::python_generated_dir(RESOCT_BINARY_DIR "/test-data", "ome-zarr-v3",
                                 RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr_v3.py");
  return dir;
}

const nlohmann::json& manifest() {
  static const nlohmann::json m = nlohmann::json::parse(test::slurp(data_dir() + "/manifest.json"));
  return m;
}

std::string bad(const std::string& name) {
  return data_dir() + "/bad/" + name + ".zarr";
}

/// Reads every brick of level 0 (where the chunk errors surface).
void read_all(const std::string& dir) {
  OmeZarrOptions o;
  o.pyramid.threads = 1;
  o.pyramid.eager_scan_voxels = 0;  // open reads metadata only; errors come from the reads
  const auto src = open_ome_zarr(dir, BrickLayout{glm::uvec3(4), 1}, o);
  std::vector<std::byte> out(src->hierarchy().layout().padded_voxels() *
                             voxel_size(src->volume().type));
  for (std::uint64_t i = 0; i < src->hierarchy().level(0).brick_count; ++i) {
    src->read_brick(src->hierarchy().key_from_linear(0, i), out);
  }
}

}  // namespace

TEST(OmeZarrV3, EveryCodecDtypeAndShardLayoutMatchesNumpy) {
  ASSERT_FALSE(data_dir().empty());
  const auto& cases = manifest()["cases"];
  ASSERT_GE(cases.size(), 200u);
  const BrickLayout layout{glm::uvec3(4), 1};
  for (const auto& c : cases) {
    const std::string name = c["name"];
    SCOPED_TRACE(name);
    const std::string axes = c["axes"];
    const auto shape = c["shape"].get<std::vector<std::uint64_t>>();
    const std::uint64_t times = axes.find('t') == std::string::npos ? 1 : shape[axes.find('t')];
    for (std::uint64_t t = 0; t < times; ++t) {
      OmeZarrOptions o;
      o.timepoint = t;
      o.pyramid.threads = 1;
      const auto src = open_ome_zarr(data_dir() + "/" + name + ".zarr", layout, o);
      EXPECT_EQ(src->multiscales().version, "0.5");
      const VolumeDesc& d = src->volume();
      for (std::uint32_t ch = 0; ch < d.channels; ++ch) {
        const auto want = test::fixture_voxels(data_dir(), c, t, ch);
        std::vector<std::byte> got(want.size());
        src->read_level_box(0, ch, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)}, got);
        ASSERT_EQ(std::memcmp(got.data(), want.data(), want.size()), 0) << "t " << t << " c " << ch;
      }
      // Stored coarser levels are subsampled, not resoct's mean: the 0.4/0.5 pair test
      // compares those.
      if (c["levels"] == 1)
        test::expect_same_bricks(test::fixture_reference(data_dir(), c, *src, t, layout), *src);
    }
  }
}

TEST(OmeZarrV3, ShardedArraysReadInnerChunksAsTheCacheUnit) {
  ASSERT_FALSE(data_dir().empty());
  const auto src = open_ome_zarr(data_dir() + "/zstd_u2_shard-end.zarr");
  const ZarrArrayMeta& m = src->array(0);
  EXPECT_EQ(m.zarr_format, 3);
  EXPECT_EQ(m.chunks, (std::vector<std::uint64_t>{4, 3, 5}));
  ASSERT_TRUE(m.v3);
  EXPECT_EQ(m.v3->shard_shape, (std::vector<std::uint64_t>{8, 6, 10}));
  EXPECT_EQ(m.v3->dimension_names, (std::vector<std::string>{"z", "y", "x"}));
  EXPECT_EQ(m.chunk_key_prefix.substr(0, 1), "c");
}

TEST(OmeZarrV3, TheSameImageAs04And05GivesIdenticalBricksAtEveryLevel) {
  ASSERT_FALSE(data_dir().empty());
  const BrickLayout layout{glm::uvec3(8), 1};
  const auto v04 = open_source(data_dir() + "/pair_v04.zarr", layout);
  const auto v05 = open_source(data_dir() + "/pair_v05.zarr", layout);
  EXPECT_EQ(v04->volume().extent, v05->volume().extent);
  EXPECT_EQ(v04->volume().spacing, v05->volume().spacing);
  EXPECT_EQ(v04->volume().channels, 2u);
  test::expect_same_bricks(*v04, *v05);
  const auto* z05 = dynamic_cast<const OmeZarrSource*>(v05.get());
  ASSERT_NE(z05, nullptr);
  EXPECT_EQ(z05->dataset_of_level(1), 1);
  EXPECT_EQ(z05->dataset_of_level(2), 2);
}

TEST(OmeZarrV3, HostileShardsAndMetadataGiveErrorsNamingFileAndOffset) {
  ASSERT_FALSE(data_dir().empty());
  const std::string shard = "/0/c/0/0/0";
  // Index crc32c over 8 entries: the checksum sits at shard end - 4; 132 index bytes.
  EXPECT_RESOCT_ERROR(read_all(bad("bad_index_crc")), ErrorCode::checksum_mismatch,
                      "bad_index_crc.zarr" + shard + ": offset ");
  EXPECT_RESOCT_ERROR(read_all(bad("truncated_index")), ErrorCode::truncated,
                      "truncated_index.zarr" + shard);
  EXPECT_RESOCT_ERROR(read_all(bad("entry_past_end")), ErrorCode::out_of_range,
                      "entry_past_end.zarr" + shard + ": offset ");
  EXPECT_RESOCT_ERROR(read_all(bad("overlapping_entries")), ErrorCode::corrupt,
                      "overlapping_entries.zarr" + shard + ": offset ");
  EXPECT_RESOCT_ERROR(read_all(bad("wrong_inner_size")), ErrorCode::size_mismatch,
                      "wrong_inner_size.zarr" + shard + " (inner chunk 0)");
  EXPECT_RESOCT_ERROR(read_all(bad("bad_chunk_crc")), ErrorCode::checksum_mismatch,
                      "bad_chunk_crc.zarr" + shard + " (inner chunk 0): offset ");
  EXPECT_RESOCT_ERROR(read_all(bad("unknown_codec")), ErrorCode::unsupported, "lzma");
  EXPECT_RESOCT_ERROR(read_all(bad("unknown_codec")), ErrorCode::unsupported,
                      "unknown_codec.zarr/0/zarr.json");
  EXPECT_RESOCT_ERROR(read_all(bad("unknown_key_encoding")), ErrorCode::unsupported, "morton");
  EXPECT_RESOCT_ERROR(read_all(bad("dimension_names_disagree")), ErrorCode::corrupt,
                      "dimension_names_disagree.zarr/0/zarr.json: key 'dimension_names[1]'");
  EXPECT_RESOCT_ERROR(read_all(bad("absurd_shard")), ErrorCode::corrupt, "inner chunks per shard");
  EXPECT_RESOCT_ERROR(read_all(bad("absurd_chunk")), ErrorCode::corrupt, "decoded bytes");
  EXPECT_RESOCT_ERROR(
      read_all(bad("unknown_data_type")), ErrorCode::unsupported,
      "unknown_data_type.zarr/0/zarr.json: key 'data_type': data type 'complex128'");
}

TEST(OmeZarrV3, ShardIndexParserChecksEntries) {
  ZarrShardingCodec s;
  s.chunk_shape = {1};
  ZarrCodec bytes;
  bytes.kind = ZarrCodecKind::bytes;
  s.index_codecs = {bytes};
  auto entry = [](std::vector<std::byte>& b, std::uint64_t o, std::uint64_t n) {
    for (int i = 0; i < 8; ++i) b.push_back(std::byte(o >> (8 * i)));
    for (int i = 0; i < 8; ++i) b.push_back(std::byte(n >> (8 * i)));
  };
  std::vector<std::byte> idx;
  entry(idx, 0, 10);
  entry(idx, ~std::uint64_t(0), ~std::uint64_t(0));
  const auto e = parse_zarr_shard_index(idx, s, 2, 10, 42, 1 << 20, "mem://shard");
  EXPECT_EQ(e[0].nbytes, 10u);
  EXPECT_TRUE(e[1].empty());
  std::vector<std::byte> half;
  entry(half, 0, 10);
  entry(half, ~std::uint64_t(0), 3);
  EXPECT_RESOCT_ERROR(parse_zarr_shard_index(half, s, 2, 10, 42, 1 << 20, "mem://shard"),
                      ErrorCode::corrupt, "mem://shard: offset 26");
  EXPECT_RESOCT_ERROR(parse_zarr_shard_index(idx, s, 3, 10, 42, 1 << 20, "mem://shard"),
                      ErrorCode::truncated, "mem://shard: offset 10");
}

TEST(OmeZarrV3, ZarritaReadsTheFixturesAsNumpyWroteThem) {
  ASSERT_FALSE(data_dir().empty());
  const std::string modules = RESOCT_SOURCE_DIR "/tests/npm/node_modules/zarrita";
  // Not a skip: a CI run without the npm test tools would validate nothing
  // (scripts/test.sh installs them; locally run scripts/install-test-tools.sh).
  ASSERT_TRUE(std::filesystem::exists(modules))
      << modules << " is missing: run scripts/install-test-tools.sh";
  const std::string cmd =
      "node " RESOCT_SOURCE_DIR "/tests/data/check_zarr_v3.mjs '" + data_dir() + "' 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(cmd.c_str(), "r"), ::pclose);
  ASSERT_TRUE(pipe);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe.get())) out += buf;
  const int status = ::pclose(pipe.release());
  EXPECT_EQ(status, 0) << out;
  EXPECT_TRUE(out.starts_with("ok ")) << out;
}

TEST(OmeZarrV3, EveryTimepointOfASeriesOpenedAtTheFirstReadsThatTimepoint) {
  ASSERT_FALSE(data_dir().empty());
  // A series opened at timepoint 0 reports the t extent and opens each other timepoint itself
  // (shared metadata, own chunk cache and region metadata): bricks of every level and region
  // metadata must be those of that timepoint's voxels. A dozen cases keep the test fast.
  const BrickLayout layout{glm::uvec3(4), 1};
  std::size_t series = 0;
  for (const auto& c : manifest()["cases"]) {
    const std::string name = c["name"];
    const std::string axes = c["axes"];
    if (axes.find('t') == std::string::npos || c["levels"] != 1) continue;
    if (++series > 12) break;
    SCOPED_TRACE(name);
    test::expect_series_of_fixture(data_dir(), c, layout);
  }
  EXPECT_GT(series, 0u);
}
