// Bad OME-Zarr input: malformed .zarray and .zattrs, unsupported features, damaged chunks and
// inconsistent stores, each an Error naming the file and key.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <lz4.h>
#include <zstd.h>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/ome_multiscales.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/formats/zarr_array.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
using test::TempDir;

namespace {

std::string zarray(const std::string& overrides = "", const std::string& drop = "") {
  std::string fields[][2] = {{"zarr_format", "2"}, {"shape", "[4, 6, 8]"}, {"chunks", "[2, 3, 4]"},
                             {"dtype", "\"<u2\""}, {"order", "\"C\""},     {"compressor", "null"},
                             {"fill_value", "0"},  {"filters", "null"}};
  std::string out = "{";
  bool first = true;
  for (auto& f : fields) {
    if (f[0] == drop) continue;
    const std::string key = "\"" + f[0] + "\"";
    std::string value = f[1];
    const auto p = overrides.find(key + ":");
    if (p != std::string::npos) {
      const auto end = overrides.find(';', p);
      value = overrides.substr(p + key.size() + 1, end - p - key.size() - 1);
    }
    out += (first ? "" : ", ") + key + ": " + value;
    first = false;
  }
  return out + "}";
}

TEST(ZarrErrors, ArrayMetadata) {
  const auto m = parse_zarr_array_meta(zarray(), "a/.zarray");
  EXPECT_EQ(m.shape, (std::vector<std::uint64_t>{4, 6, 8}));
  EXPECT_EQ(m.chunk_grid(), (std::vector<std::uint64_t>{2, 2, 2}));
  EXPECT_EQ(m.chunk_key(std::vector<std::uint64_t>{1, 0, 1}), "1.0.1");
  auto bad = [](const std::string& json, ErrorCode code, const std::string& needle) {
    EXPECT_RESOCT_ERROR(parse_zarr_array_meta(json, "a/.zarray"), code, needle);
  };
  bad("{not json", ErrorCode::corrupt, "a/.zarray: not valid JSON");
  bad("[1, 2]", ErrorCode::corrupt, "(root)");
  bad(zarray("\"zarr_format\":3;"), ErrorCode::unsupported_version, "zarr_format");
  bad(zarray("", "shape"), ErrorCode::corrupt, "key 'shape': missing");
  bad(zarray("\"shape\":[4, 0, 8];"), ErrorCode::corrupt, "key 'shape'");
  bad(zarray("\"chunks\":[2, 3];"), ErrorCode::corrupt, "key 'chunks': rank 2");
  bad(zarray("\"chunks\":[2000000, 2000000, 2];"), ErrorCode::corrupt, "decoded bytes");
  bad(zarray("\"dtype\":\"<i8\";"), ErrorCode::unsupported, "key 'dtype'");
  bad(zarray("\"dtype\":\"|i2\";"), ErrorCode::unsupported, "key 'dtype'");  // no byte order
  bad(zarray("\"dtype\":\"<i2\";\"fill_value\":40000;"), ErrorCode::corrupt, "-32768..32767");
  bad(zarray("\"dtype\":[[\"a\", \"<u2\"]];"), ErrorCode::unsupported, "structured");
  bad(zarray("\"order\":\"F\";"), ErrorCode::unsupported, "key 'order'");
  bad(zarray("\"filters\":[{\"id\": \"delta\"}];"), ErrorCode::unsupported, "key 'filters'");
  bad(zarray("\"compressor\":{\"id\": \"bz2\"};"), ErrorCode::unsupported, "key 'compressor'");
  bad(zarray("\"compressor\":{\"level\": 1};"), ErrorCode::corrupt, "key 'compressor'");
  bad(zarray("\"fill_value\":-1;"), ErrorCode::corrupt, "key 'fill_value'");
  bad(zarray("\"fill_value\":\"banana\";"), ErrorCode::corrupt, "key 'fill_value'");
  const auto nan = parse_zarr_array_meta(zarray("\"dtype\":\">f4\";\"fill_value\":\"NaN\";"), "x");
  EXPECT_TRUE(std::isnan(nan.fill_value));
  EXPECT_EQ(nan.endian, Endian::big);
}

std::vector<std::byte> as_bytes(const std::vector<std::uint8_t>& v) {
  std::vector<std::byte> b(v.size());
  std::memcpy(b.data(), v.data(), v.size());
  return b;
}

TEST(ZarrErrors, ChunkDecoding) {
  ZarrArrayMeta m = parse_zarr_array_meta(zarray(), "a/.zarray");
  const std::size_t n = std::size_t(m.chunk_bytes());  // 2*3*4 u16 = 48 bytes
  std::vector<std::uint8_t> raw(n);
  for (std::size_t i = 0; i < n; ++i) raw[i] = std::uint8_t(i);
  // none: exact size required.
  EXPECT_EQ(decode_zarr_chunk(m, as_bytes(raw), "a/0.0.0").size(), n);
  raw.pop_back();
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes(raw), "a/0.0.0"), ErrorCode::size_mismatch,
                      "a/0.0.0");
  raw.push_back(0);
  // zstd: a frame of the wrong size, then garbage.
  m.compressor = ZarrCompressor::zstd;
  std::vector<std::uint8_t> z(ZSTD_compressBound(n - 2));
  z.resize(ZSTD_compress(z.data(), z.size(), raw.data(), n - 2, 1));
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes(z), "a/1.0.0"), ErrorCode::size_mismatch,
                      "a/1.0.0");
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes({1, 2, 3, 4, 5}), "a/1.0.0"),
                      ErrorCode::decompress_failed, "a/1.0.0");
  // lz4 (numcodecs framing): a header announcing another size, a short buffer, a bad block.
  m.compressor = ZarrCompressor::lz4;
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes({1, 2}), "a/0.1.0"), ErrorCode::corrupt,
                      "4-byte header");
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes({47, 0, 0, 0, 1}), "a/0.1.0"),
                      ErrorCode::size_mismatch, "header says 47");
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes({48, 0, 0, 0, 0xff, 0xff}), "a/0.1.0"),
                      ErrorCode::decompress_failed, "a/0.1.0");
  // blosc: not a frame.
  m.compressor = ZarrCompressor::blosc;
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes(std::vector<std::uint8_t>(40, 7)), "a/0.0.1"),
                      ErrorCode::corrupt, "a/0.0.1: offset 0: not a valid blosc frame");
  // zlib / gzip: garbage and truncation.
  m.compressor = ZarrCompressor::zlib;
  EXPECT_RESOCT_ERROR(
      decode_zarr_chunk(m, as_bytes({0x78, 0x9c, 0xff, 0xff, 0xff, 0xff}), "a/0.0.1"),
      ErrorCode::decompress_failed, "a/0.0.1");
  m.compressor = ZarrCompressor::gzip;
  EXPECT_RESOCT_ERROR(decode_zarr_chunk(m, as_bytes({0x1f, 0x8b}), "a/0.0.1"),
                      ErrorCode::size_mismatch, "a/0.0.1");
}

std::string zattrs(const std::string& axes, const std::string& datasets,
                   const std::string& version = "0.4") {
  return R"({"multiscales": [{"version": ")" + version + R"(", "axes": )" + axes +
         R"(, "datasets": )" + datasets + "}]}";
}

const std::string kAxes = R"([{"name": "z"}, {"name": "y"}, {"name": "x"}])";
const std::string kSets =
    R"([{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}])";

TEST(ZarrErrors, MultiscalesMetadata) {
  const auto ms = parse_ome_multiscales(zattrs(kAxes, kSets), "i/.zattrs");
  EXPECT_EQ(ms.axes, (std::vector<char>{'z', 'y', 'x'}));
  auto bad = [](const std::string& json, ErrorCode code, const std::string& needle) {
    EXPECT_RESOCT_ERROR(parse_ome_multiscales(json, "i/.zattrs"), code, needle);
  };
  bad("{\"omero\": {}}", ErrorCode::bad_magic, "no 'multiscales'");
  bad("{", ErrorCode::corrupt, "not valid JSON");
  bad(zattrs(kAxes, kSets, "0.3"), ErrorCode::unsupported_version, "multiscales[0].version");
  bad(zattrs(R"([{"name": "x"}, {"name": "z"}])", kSets), ErrorCode::corrupt, "in that order");
  bad(zattrs(R"([{"name": "q"}])", kSets), ErrorCode::corrupt, "multiscales[0].axes[0]");
  bad(zattrs(R"([{"name": "t"}, {"name": "c"}])", kSets), ErrorCode::corrupt, "no spatial axis");
  bad(zattrs(kAxes, "[]"), ErrorCode::corrupt, "multiscales[0].datasets");
  bad(zattrs(
          kAxes,
          R"([{"path": "../up", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}])"),
      ErrorCode::corrupt, "datasets[0].path");
  bad(zattrs(
          kAxes,
          R"([{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1]}]}])"),
      ErrorCode::corrupt, "datasets[0].coordinateTransformations[0].scale");
  bad(zattrs(
          kAxes,
          R"([{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, -1, 1]}]}])"),
      ErrorCode::corrupt, "positive");
  bad(zattrs(kAxes, R"([{"path": "0", "coordinateTransformations": []}])"), ErrorCode::corrupt,
      "no scale transformation");
  bad(zattrs(kAxes, R"([{"path": "0"}])"), ErrorCode::corrupt,
      "datasets[0].coordinateTransformations': missing");
}

void write_text(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  test::write_bytes(path, std::vector<std::uint8_t>(text.begin(), text.end()));
}

TEST(ZarrErrors, InconsistentStoresAndDamagedChunks) {
  TempDir dir;
  const std::string root = dir.file("img.zarr");
  write_text(root + "/.zattrs", zattrs(kAxes, kSets));
  // No .zarray for dataset "0".
  EXPECT_RESOCT_ERROR(open_ome_zarr(root), ErrorCode::corrupt, "img.zarr/0/.zarray: missing");
  // Rank disagrees with the axes.
  write_text(root + "/0/.zarray", zarray("\"shape\":[4, 6];\"chunks\":[2, 3];"));
  EXPECT_RESOCT_ERROR(open_ome_zarr(root), ErrorCode::corrupt, "rank 2 differs");
  // A chunk of the wrong size (uncompressed chunks must hold 48 bytes) fails the open pass,
  // naming the chunk file.
  write_text(root + "/0/.zarray", zarray());
  write_text(root + "/0/1.1.1", std::string(40, 'x'));
  EXPECT_RESOCT_ERROR(open_ome_zarr(root), ErrorCode::size_mismatch, "img.zarr/0/1.1.1");
  std::filesystem::remove(root + "/0/1.1.1");
  EXPECT_NO_THROW(open_ome_zarr(root));
  EXPECT_RESOCT_ERROR(
      [&] {
        OmeZarrOptions o;
        o.timepoint = 1;
        open_ome_zarr(root, {}, o);
      }(),
      ErrorCode::invalid_argument, "timepoint");
  // Nothing zarr-like at all.
  TempDir empty;
  EXPECT_RESOCT_ERROR(open_ome_zarr(empty.path().string()), ErrorCode::bad_magic,
                      "no OME-Zarr image");
}

}  // namespace
