// NRRD: files written by the test from the NRRD format description (attached and detached data,
// raw and gzip encodings, both byte orders, every sample type, channel axes first or last,
// spacings / space directions, byte and line skips), and malformed headers and files.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/nrrd.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/io/open_source.hpp"
#include "support/expect_error.hpp"
#include "support/gzip_bytes.hpp"
#include "support/level0_values.hpp"

using namespace resoct;
using test::TempDir;

namespace {

std::vector<std::uint8_t> text_bytes(const std::string& s) {
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

/// Sample i of the test volume as the NRRD type stores it, appended in the given byte order.
void append_sample(std::vector<std::uint8_t>& b, const std::string& type, double v, bool big) {
  std::uint8_t tmp[8];
  std::size_t n = 0;
  auto put = [&](auto x) { std::memcpy(tmp, &x, n = sizeof x); };
  if (type == "uchar") put(std::uint8_t(v));
  if (type == "signed char") put(std::int8_t(v));
  if (type == "short") put(std::int16_t(v));
  if (type == "ushort") put(std::uint16_t(v));
  if (type == "int") put(std::int32_t(v));
  if (type == "uint") put(std::uint32_t(v));
  if (type == "float") put(float(v));
  if (type == "double") put(v);
  for (std::size_t i = 0; i < n; ++i) b.push_back(big ? tmp[n - 1 - i] : tmp[i]);
}

/// Sample i in the file's units; exact in every mapping (|v| < 2^24 for the 32-bit integers).
double sample_value(const std::string& type, std::size_t i) {
  if (type == "uchar") return double((i * 13) % 256);
  if (type == "signed char") return double(std::int64_t(i * 13 % 256) - 128);
  if (type == "short") return double(std::int64_t(i * 211 % 4000) - 2000);
  if (type == "ushort") return double((i * 977) % 65536);
  if (type == "int") return double(std::int64_t(i * 99991 % 16000000) - 8000000);
  if (type == "uint") return double(i * 99991 % 16000000 + 3);
  return double(i) * 0.125 - 3.0;
}

TEST(Nrrd, TypesEncodingsByteOrdersAttachedAndDetached) {
  TempDir dir;
  const glm::u64vec3 e(6, 5, 4);
  const std::size_t n = 120;
  for (const std::string type :
       {"uchar", "signed char", "short", "ushort", "int", "uint", "float", "double"}) {
    for (bool gz : {false, true}) {
      for (bool big : {false, true}) {
        for (bool detached : {false, true}) {
          SCOPED_TRACE(type + (gz ? " gzip" : " raw") + (big ? " big" : " little") +
                       (detached ? " detached" : " attached"));
          std::vector<std::uint8_t> data;
          for (std::size_t i = 0; i < n; ++i) append_sample(data, type, sample_value(type, i), big);
          if (gz) data = test::gzip_bytes(data);
          std::string head = "NRRD0004\n# a comment\ntype: " + type +
                             "\ndimension: 3\nsizes: 6 5 4\nencoding: " + (gz ? "gzip" : "raw") +
                             "\nendian: " + (big ? "big" : "little") +
                             "\nspacings: 0.5 0.75 2\nsome key:=some value\n";
          std::string path;
          if (detached) {
            head += "data file: vol.raw\n";
            test::write_bytes(dir.file("vol.raw"), data);
            path = dir.file("vol.nhdr");
            test::write_bytes(path, text_bytes(head));
          } else {
            auto file = text_bytes(head + "\n");
            file.insert(file.end(), data.begin(), data.end());
            path = dir.file("vol.nrrd");
            test::write_bytes(path, file);
          }
          const auto src = open_source(path, BrickLayout{glm::uvec3(4), 1});
          const VolumeDesc& d = src->volume();
          EXPECT_EQ(d.extent, e);
          EXPECT_EQ(d.spacing, glm::dvec3(0.5, 0.75, 2));
          const bool one = type == "uchar" || type == "signed char";
          const bool two = type == "short" || type == "ushort";
          EXPECT_EQ(d.type, one ? VoxelType::u8 : two ? VoxelType::u16 : VoxelType::f32);
          EXPECT_EQ(d.data_type.has_value(),
                    type != "uchar" && type != "ushort" && type != "float");
          // Values in the file's units: stored minus the mapping's offset (128 for signed char,
          // 32768 for short).
          const auto v = level0_values(*src, 0);
          for (std::size_t i = 0; i < n; ++i) {
            ASSERT_EQ(v[i] - d.value_offset(), sample_value(type, i)) << i;
          }
        }
      }
    }
  }
}

TEST(Nrrd, ChannelAxesSpaceDirectionsAndSkips) {
  TempDir dir;
  // 4-D with the first axis a vector of 3 channels (interleaved), directions give spacing.
  std::vector<std::uint8_t> data;
  for (std::size_t i = 0; i < 3 * 24; ++i) data.push_back(std::uint8_t(i));
  auto file = text_bytes(
      "NRRD0005\ntype: uint8\ndimension: 4\nsizes: 3 4 3 2\nkinds: vector domain domain "
      "domain\nencoding: raw\nspace dimension: 3\nspace directions: none (0,1.5,0) (2,0,0) "
      "(0,0,-3)\n\n");
  file.insert(file.end(), data.begin(), data.end());
  test::write_bytes(dir.file("vec.nrrd"), file);
  const auto vec = open_source(dir.file("vec.nrrd"), BrickLayout{glm::uvec3(4), 1});
  // Served in world order (docs/formats.md "Physical placement"): index i steps world +y,
  // j world +x, k world -z, so served x = j, y = i, z = 1 - k; spacing the step lengths; the
  // origin the corner of the served voxel 0 (stored (0, 0, 1), centred at (0, 0, -3)).
  EXPECT_EQ(vec->volume().channels, 3u);
  EXPECT_EQ(vec->volume().extent, glm::u64vec3(3, 4, 2));
  EXPECT_EQ(vec->volume().spacing, glm::dvec3(2, 1.5, 3));
  EXPECT_EQ(vec->volume().origin, glm::dvec3(-1.0, -0.75, -4.5));
  for (std::uint32_t c = 0; c < 3; ++c) {
    const auto v = level0_values(*vec, c);
    for (std::size_t x = 0; x < 3; ++x) {
      for (std::size_t y = 0; y < 4; ++y) {
        for (std::size_t z = 0; z < 2; ++z) {
          const std::size_t stored = y + 4 * (x + 3 * (1 - z));  // i + 4 (j + 3 k)
          ASSERT_EQ(v[x + 3 * (y + 4 * z)], double(stored * 3 + c)) << x << " " << y << " " << z;
        }
      }
    }
  }
  // `space origin` places the first voxel's centre; a left-posterior-superior space is served
  // in right-anterior-superior order (x and y reversed), as NIfTI is.
  std::vector<std::uint8_t> ramp;
  for (std::size_t i = 0; i < 8; ++i) ramp.push_back(std::uint8_t(i));
  auto lps = text_bytes(
      "NRRD0005\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace: "
      "left-posterior-superior\nspace directions: (0.5,0,0) (0,0.5,0) (0,0,2)\nspace origin: "
      "(10,20,30)\n\n");
  lps.insert(lps.end(), ramp.begin(), ramp.end());
  test::write_bytes(dir.file("lps.nrrd"), lps);
  const auto placed = open_source(dir.file("lps.nrrd"), BrickLayout{glm::uvec3(4), 1});
  EXPECT_EQ(placed->volume().spacing, glm::dvec3(0.5, 0.5, 2));
  // RAS centre of stored voxel (1, 1, 0) is (-10.5, -20.5, 30); the corner is half a voxel lower.
  EXPECT_EQ(placed->volume().origin, glm::dvec3(-10.75, -20.75, 29));
  EXPECT_EQ(level0_values(*placed, 0),
            (std::vector<double>{3, 2, 1, 0, 7, 6, 5, 4}));  // x and y reversed, z kept
  // 4-D with the last axis 2 channels one after another; a detached file with line and byte
  // skips before the data.
  std::vector<std::uint8_t> skipped = text_bytes("junk line 1\njunk line 2\nXYZ");
  for (std::size_t i = 0; i < 2 * 8; ++i) append_sample(skipped, "ushort", double(i * 1000), true);
  test::write_bytes(dir.file("t.bin"), skipped);
  test::write_bytes(dir.file("t.nhdr"),
                    text_bytes("NRRD0004\ntype: unsigned short\ndimension: 4\nsizes: 2 2 2 "
                               "2\nendian: big\nencoding: raw\nline skip: 2\nbyte skip: 3\n"
                               "datafile: t.bin\n"));
  const auto t = open_source(dir.file("t.nhdr"), BrickLayout{glm::uvec3(4), 1});
  EXPECT_EQ(t->volume().channels, 2u);
  for (std::uint32_t c = 0; c < 2; ++c) {
    const auto v = level0_values(*t, c);
    for (std::size_t i = 0; i < 8; ++i) ASSERT_EQ(v[i], double((c * 8 + i) * 1000));
  }
  // byte skip -1: the data are the last bytes of the file.
  auto tail = text_bytes(
      "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 3 2\nencoding: raw\n"
      "byte skip: -1\n\n0123456789");
  test::write_bytes(dir.file("tail.nrrd"), tail);
  const auto s2 = open_source(dir.file("tail.nrrd"), BrickLayout{glm::uvec3(4), 1});
  EXPECT_EQ(s2->volume().extent, glm::u64vec3(3, 2, 1));
  EXPECT_EQ(level0_values(*s2, 0), (std::vector<double>{'4', '5', '6', '7', '8', '9'}));
}

TEST(Nrrd, MalformedHeadersAndFiles) {
  auto parse = [](const std::string& s) { return parse_nrrd_header(s, "h.nrrd"); };
  const std::string ok = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n";
  EXPECT_NO_THROW(parse(ok));
  EXPECT_RESOCT_ERROR(parse("NRRX0004\n"), ErrorCode::bad_magic, "h.nrrd");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n\n"),
                      ErrorCode::corrupt, "'encoding' is missing");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: longlong\ndimension: 1\nsizes: 2\nencoding: raw\n\n"),
                      ErrorCode::unsupported, "offset 9: NRRD field 'type'");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2\nencoding: raw\n\n"),
                      ErrorCode::corrupt, "NRRD field 'sizes'");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 0 2\nencoding: raw\n\n"),
                      ErrorCode::corrupt, ">= 1");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: "
                            "bzip2\n\n"),
                      ErrorCode::unsupported, "encoding");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 5\nsizes: 2 2 2 2 2\nencoding: "
                            "raw\n\n"),
                      ErrorCode::unsupported, "dimension");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: x\nsizes: 2\nencoding: raw\n\n"),
                      ErrorCode::corrupt, "integer");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\nthis line has no separator\n\n"), ErrorCode::corrupt,
                      "offset 9");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 1\nsizes: 2\nencoding: raw\n"
                            "data file: LIST\n\n"),
                      ErrorCode::unsupported, "data file");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                            "space directions: (1,0,0) (0,1,0) (0,0,q)\n\n"),
                      ErrorCode::corrupt, "space directions");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: "
                            "raw\nendian: middle\n\n"),
                      ErrorCode::corrupt, "endian");
  EXPECT_RESOCT_ERROR(parse("NRRD0004\ntype: uchar\ndimension: 2\nsizes: 60000000000 "
                            "60000000000\nencoding: raw\n\n"),
                      ErrorCode::overflow, "sizes");

  TempDir dir;
  auto file = text_bytes(ok);
  file.insert(file.end(), 7, 1);  // one byte short
  test::write_bytes(dir.file("short.nrrd"), file);
  EXPECT_RESOCT_ERROR(open_nrrd(dir.file("short.nrrd")), ErrorCode::truncated, "short.nrrd");
  auto gz = text_bytes("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\n");
  auto packed = test::gzip_bytes(std::vector<std::uint8_t>(8, 3));
  packed.resize(packed.size() - 10);
  gz.insert(gz.end(), packed.begin(), packed.end());
  test::write_bytes(dir.file("cut.nrrd"), gz);
  EXPECT_RESOCT_ERROR(open_nrrd(dir.file("cut.nrrd")), ErrorCode::truncated, "cut.nrrd");
  // A header announcing far more than the stream holds: truncated, without allocating it.
  auto huge = text_bytes(
      "NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 10000\nencoding: gzip\n\n");
  const auto small = test::gzip_bytes(std::vector<std::uint8_t>(64, 1));
  huge.insert(huge.end(), small.begin(), small.end());
  test::write_bytes(dir.file("huge.nrrd"), huge);
  EXPECT_RESOCT_ERROR(open_nrrd(dir.file("huge.nrrd")), ErrorCode::truncated, "holds 64 bytes");
  test::write_bytes(dir.file("d.nhdr"),
                    text_bytes("NRRD0004\ntype: uchar\ndimension: 1\nsizes: 4\nencoding: "
                               "raw\ndata file: missing.raw\n"));
  EXPECT_RESOCT_ERROR(open_nrrd(dir.file("d.nhdr")), ErrorCode::io, "missing.raw");
}

}  // namespace
