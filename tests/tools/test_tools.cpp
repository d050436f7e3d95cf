// Runs the installed command-line tools as processes: exit codes, the stores they write (compared
// brick by brick with the sources they came from), resoct-info's JSON, and the one-line errors
// for bad input that must leave nothing behind.

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <bit>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/io/store/test_brick_store_util.hpp"
#include "support/brick_compare.hpp"
#include "support/tool_process.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/sources/brick_error.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/sources/procedural_source.hpp"

using namespace resoct;
using resoct::test::expect_same_bricks;
using resoct::test::shell_quote;
using resoct::test::slurp;
using resoct::test::TempDir;
using resoct::test::ToolRun;

namespace {

ToolRun run(const TempDir& dir, const std::string& tool, const std::string& args) {
  return resoct::test::run_tool_process(dir.path().string(), tool, args);
}

std::size_t line_count(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

BrickLayout layout_of(std::uint32_t b, std::uint32_t halo = 1) {
  BrickLayout l;
  l.brick_size = glm::uvec3(b);
  l.halo = halo;
  return l;
}

TEST(Tools, ConvertProceduralIsBitExactAndShowsPlainProgress) {
  TempDir dir;
  const std::string out = dir.file("tubes.rbs");
  const ToolRun r =
      run(dir, RESOCT_CONVERT,
          "procedural:tubes:64x64x64 " + shell_quote(out) + " --brick 16 --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Wrote " + out), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("MB/s"), std::string::npos) << r.out;
  // Not a terminal: plain "writing ...: NN%" lines on stderr, at most one per 10 %.
  EXPECT_NE(r.err.find("writing " + out + ": 100%"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos);
  EXPECT_LE(line_count(r.err), 11u) << r.err;

  const BrickStoreSource store(out);
  const ProceduralSource proc("procedural:tubes:64x64x64", layout_of(16));
  EXPECT_EQ(store.stats().codec, Codec::lz4);
  expect_same_bricks(store, proc);
}

TEST(Tools, ConvertWithZstdMultiChannelAndWideHalo) {
  TempDir dir;
  const std::string out = dir.file("sphere.rbs");
  const ToolRun r = run(dir, RESOCT_CONVERT,
                        "procedural:sphere:40x30x20:2 " + shell_quote(out) +
                            " --codec zstd --level 5 --brick 8x8x8 --halo 2 --metadata-block 8");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const BrickStoreSource store(out);
  EXPECT_EQ(store.stats().codec, Codec::zstd);
  EXPECT_EQ(store.stats().codec_level, 5);
  EXPECT_EQ(store.metadata_block(), 8u);
  expect_same_bricks(store, ProceduralSource("procedural:sphere:40x30x20:2", layout_of(8, 2)));
}

TEST(Tools, InfoJsonMatchesTheStore) {
  TempDir dir;
  const std::string out = dir.file("tubes.rbs");
  ASSERT_EQ(
      run(dir, RESOCT_CONVERT, "procedural:tubes:64x64x64 " + shell_quote(out) + " --brick 16")
          .exit_code,
      0);
  const ToolRun r = run(dir, RESOCT_INFO, shell_quote(out) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "store");
  EXPECT_EQ(j["source"], out);
  EXPECT_EQ(j["volume"]["extent"], nlohmann::json({64, 64, 64}));
  EXPECT_EQ(j["volume"]["type"], "u8");
  EXPECT_EQ(j["volume"]["channels"], 1);
  EXPECT_EQ(j["volume"]["ranges"], nlohmann::json::parse("[[0.0, 255.0]]"));
  EXPECT_EQ(j["layout"]["brick_size"], nlohmann::json({16, 16, 16}));
  EXPECT_EQ(j["layout"]["halo"], 1);
  EXPECT_EQ(j["store"]["codec"], "lz4");
  EXPECT_EQ(j["store"]["file_bytes"], std::filesystem::file_size(out));

  // Level structure: 64³ in 16³ bricks halves to 32³ (2³ bricks) and 16³ (one brick).
  ASSERT_EQ(j["levels"].size(), 3u);
  const std::uint64_t extents[] = {64, 32, 16};
  const std::uint64_t bricks[] = {4, 2, 1};
  // Brute force: read every stored brick and count the all-zero ones and the payload sizes.
  const BrickStoreSource store(out);
  const BrickHierarchy& h = store.hierarchy();
  std::vector<std::byte> buf(h.layout().padded_voxels());
  std::uint64_t total_empty = 0, total_bricks = 0;
  for (std::uint32_t l = 0; l < 3; ++l) {
    const auto& lj = j["levels"][l];
    EXPECT_EQ(lj["extent"], nlohmann::json({extents[l], extents[l], extents[l]})) << l;
    EXPECT_EQ(lj["factor"], nlohmann::json({1u << l, 1u << l, 1u << l})) << l;
    EXPECT_EQ(lj["bricks"], nlohmann::json({bricks[l], bricks[l], bricks[l]})) << l;
    const std::uint64_t count = bricks[l] * bricks[l] * bricks[l];
    EXPECT_EQ(lj["brick_count"], count);
    EXPECT_EQ(lj["uncompressed_bytes"], count * 18 * 18 * 18);
    std::uint64_t empty = 0;
    for (std::uint64_t i = 0; i < count; ++i) {
      store.read_brick(h.key_from_linear(0, h.level(l).first_brick + i), buf);
      bool zero = true;
      for (std::byte b : buf) zero = zero && b == std::byte{0};
      empty += zero ? 1 : 0;
    }
    EXPECT_EQ(lj["empty_bricks"], empty) << "level " << l;
    EXPECT_DOUBLE_EQ(lj["empty_fraction"].get<double>(), double(empty) / double(count));
    EXPECT_LT(lj["compressed_bytes"].get<std::uint64_t>(),
              lj["uncompressed_bytes"].get<std::uint64_t>());
    EXPECT_DOUBLE_EQ(lj["compression_ratio"].get<double>(),
                     lj["uncompressed_bytes"].get<double>() / lj["compressed_bytes"].get<double>());
    total_empty += empty;
    total_bricks += count;
  }
  EXPECT_GT(total_empty, 0u);  // tubes are sparse: some bricks must be empty
  EXPECT_EQ(j["total"]["brick_count"], total_bricks);
  EXPECT_EQ(j["total"]["empty_bricks"], total_empty);
  EXPECT_LT(j["total"]["compressed_bytes"].get<std::uint64_t>(), std::filesystem::file_size(out));

  const ToolRun text = run(dir, RESOCT_INFO, shell_quote(out));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("lz4"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("total"), std::string::npos) << text.out;
}

TEST(Tools, ConvertWithBrickErrorsStoresTheMeasuredErrors) {
  TempDir dir;
  const std::string out = dir.file("sphere.rbs");
  const std::string spec = "procedural:sphere:64x64x64";
  const ToolRun r = run(dir, RESOCT_CONVERT,
                        spec + " " + shell_quote(out) + " --brick 16 --brick-errors --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Brick errors stored"), std::string::npos) << r.out;
  const BrickStoreSource store(out);
  ASSERT_TRUE(store.stats().brick_errors);
  const ProceduralSource proc(spec, layout_of(16));
  expect_same_bricks(store, proc);
  // The errors are the procedural source's own measurements, and level 1 of a sphere is not
  // exact everywhere.
  const BrickHierarchy& h = store.hierarchy();
  std::vector<std::byte> buf(h.layout().padded_voxels() * 4);
  double largest = 0.0;
  for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i) {
    const BrickKey key = h.key_from_linear(0, i);
    proc.read_brick(key, buf);
    const double want = double(brick_error_to_float(proc.brick_error(key, buf)));
    ASSERT_EQ(store.brick_error(key, buf), want) << "brick " << i;
    if (key.level() == 1) largest = std::max(largest, want);
  }
  EXPECT_GT(largest, 0.0);

  const ToolRun info = run(dir, RESOCT_INFO, shell_quote(out) + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["store"]["brick_errors"], true);
  EXPECT_EQ(j["levels"][1]["max_error"].get<double>(), largest);
  EXPECT_EQ(j["levels"][0]["max_error"].get<double>(), 0.0);
  const ToolRun text = run(dir, RESOCT_INFO, shell_quote(out));
  EXPECT_NE(text.out.find("brick errors stored"), std::string::npos) << text.out;
  // A store converted without the flag says nothing of errors.
  const std::string plain = dir.file("plain.rbs");
  ASSERT_EQ(run(dir, RESOCT_CONVERT, spec + " " + shell_quote(plain) + " --brick 16").exit_code, 0);
  const nlohmann::json p =
      nlohmann::json::parse(run(dir, RESOCT_INFO, shell_quote(plain) + " --json").out);
  EXPECT_EQ(p["store"]["brick_errors"], false);
  EXPECT_FALSE(p["levels"][1].contains("max_error"));
}

TEST(Tools, InfoOnAProceduralSourceShowsTheHierarchyOnly) {
  TempDir dir;
  const std::string spec = "procedural:cells:256x256x40:16";
  const ToolRun r = run(dir, RESOCT_INFO, spec + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "procedural");
  EXPECT_FALSE(j.contains("store"));
  const BrickHierarchy h(ProceduralSource(spec).volume(), BrickLayout{});
  ASSERT_EQ(j["levels"].size(), h.level_count());
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    EXPECT_EQ(j["levels"][l]["brick_count"], h.level(l).brick_count * 16) << l;
    EXPECT_FALSE(j["levels"][l].contains("compressed_bytes"));
  }
  EXPECT_EQ(j["volume"]["type"], "u16");
  const ToolRun text = run(dir, RESOCT_INFO, spec);
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("hierarchy only"), std::string::npos) << text.out;
}

// Encodes u16 values big-endian by shifts, independent of the code under test.
std::vector<std::uint8_t> big_endian_u16(const std::vector<std::uint16_t>& v) {
  std::vector<std::uint8_t> b;
  for (std::uint16_t x : v) {
    b.push_back(std::uint8_t(x >> 8));
    b.push_back(std::uint8_t(x & 0xFF));
  }
  return b;
}

TEST(Tools, ConvertRawRoundTrip) {
  TempDir dir;
  const glm::u64vec3 e{30, 20, 10};
  const std::size_t n = std::size_t(e.x * e.y * e.z) * 2;  // two channels
  std::mt19937 rng(42);
  std::vector<std::uint16_t> values(n);
  for (auto& v : values) v = std::uint16_t(rng() % 4096);
  std::vector<std::uint8_t> file(32, 0xEE);  // a 32-byte header to skip
  const auto body = big_endian_u16(values);
  file.insert(file.end(), body.begin(), body.end());
  const std::string raw = dir.file("cells.raw"), out = dir.file("cells.rbs");
  resoct::test::write_bytes(raw, file);
  const ToolRun r = run(dir, RESOCT_CONVERT,
                        shell_quote(raw) + " " + shell_quote(out) +
                            " --dims 30x20x10 --type u16 --endian big --channels 2 --offset 32"
                            " --spacing 0.5,0.5,2 --range 0,4095 --brick 8 --codec zstd");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const BrickStoreSource store(out);
  EXPECT_EQ(store.volume().spacing, glm::dvec3(0.5, 0.5, 2.0));
  EXPECT_EQ(store.volume().range(1), (ValueRange{0.0, 4095.0}));
  VolumeDesc d;
  d.extent = e;
  d.type = VoxelType::u16;
  d.channels = 2;
  d.spacing = {0.5, 0.5, 2.0};
  d.ranges.assign(2, ValueRange{0.0, 4095.0});
  expect_same_bricks(store, InMemorySource(DenseVolume::from_values(d, values), layout_of(8)));
}

TEST(Tools, ConvertRawF32TakesItsRangeFromTheData) {
  TempDir dir;
  std::vector<std::uint8_t> file;
  float lo = 1e9f, hi = -1e9f;
  std::mt19937 rng(7);
  for (int i = 0; i < 16 * 16 * 16; ++i) {
    const float v = float(int(rng() % 8001) - 3000) / 1000.0f;  // -3 .. 5
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    const auto bits = std::bit_cast<std::uint32_t>(v);
    for (int k = 0; k < 4; ++k) file.push_back(std::uint8_t(bits >> (8 * k)));
  }
  const std::string raw = dir.file("f.raw"), out = dir.file("f.rbs");
  resoct::test::write_bytes(raw, file);
  const ToolRun r = run(dir, RESOCT_CONVERT,
                        shell_quote(raw) + " " + shell_quote(out) + " --dims 16x16x16 --type f32");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const BrickStoreSource store(out);
  EXPECT_EQ(store.volume().range(0), (ValueRange{double(lo), double(hi)}));
}

// int16 CT as users have it: the store keeps u16 + 32768 (two bytes, exact), remembers that the
// file was int16, and resoct-info reports the type and the window in the file's units. A
// float64 file is kept as f32 and the conversion says that it rounds.
TEST(Tools, ConvertRawSignedAndWideTypes) {
  TempDir dir;
  const glm::u64vec3 e{12, 10, 8};
  std::vector<std::uint8_t> i16_file;
  std::vector<std::uint16_t> stored;  // what the cache must hold: value + 32768
  for (std::size_t i = 0; i < e.x * e.y * e.z; ++i) {
    const auto v = std::int16_t(std::int64_t(i * 37 % 3000) - 1024);  // air near -1024
    const auto bits = std::uint16_t(v);
    i16_file.push_back(std::uint8_t(bits & 0xFF));
    i16_file.push_back(std::uint8_t(bits >> 8));
    stored.push_back(std::uint16_t(std::int32_t(v) + 32768));
  }
  const std::string raw = dir.file("ct.raw"), out = dir.file("ct.rbs");
  resoct::test::write_bytes(raw, i16_file);
  const ToolRun r = run(dir, RESOCT_CONVERT,
                        shell_quote(raw) + " " + shell_quote(out) +
                            " --dims 12x10x8 --type i16 --range -1000,2000 --brick 8");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const BrickStoreSource store(out);
  EXPECT_EQ(store.volume().type, VoxelType::u16);
  EXPECT_EQ(store.volume().data_type, DataType::i16);
  EXPECT_EQ(store.volume().range(0), (ValueRange{31768.0, 34768.0}));
  EXPECT_EQ(store.volume().data_range(0), (ValueRange{-1000.0, 2000.0}));
  VolumeDesc d;
  d.extent = e;
  d.type = VoxelType::u16;
  d.data_type = DataType::i16;
  d.ranges = {ValueRange{31768.0, 34768.0}};
  expect_same_bricks(store, InMemorySource(DenseVolume::from_values(d, stored), layout_of(8)));
  const ToolRun info = run(dir, RESOCT_INFO, shell_quote(out) + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["volume"]["type"], "i16");
  EXPECT_EQ(j["volume"]["stored_type"], "u16");
  EXPECT_EQ(j["volume"]["value_offset"], 32768.0);
  EXPECT_EQ(j["volume"]["exact"], true);
  EXPECT_EQ(j["volume"]["ranges"], nlohmann::json::parse("[[-1000.0, 2000.0]]"));
  const ToolRun text = run(dir, RESOCT_INFO, shell_quote(out));
  EXPECT_NE(text.out.find("i16 (kept as u16, value + 32768: exact)"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("[-1000, 2000]"), std::string::npos) << text.out;

  std::vector<std::uint8_t> f64_file;
  for (std::size_t i = 0; i < e.x * e.y * e.z; ++i) {
    const double v = double(i) * 0.1 - 3.0;
    const auto bits = std::bit_cast<std::uint64_t>(v);
    for (int k = 0; k < 8; ++k) f64_file.push_back(std::uint8_t(bits >> (8 * k)));
  }
  const std::string raw64 = dir.file("f.raw"), out64 = dir.file("f.rbs");
  resoct::test::write_bytes(raw64, f64_file);
  const ToolRun r64 =
      run(dir, RESOCT_CONVERT,
          shell_quote(raw64) + " " + shell_quote(out64) + " --dims 12x10x8 --type f64");
  ASSERT_EQ(r64.exit_code, 0) << r64.err;
  EXPECT_NE(r64.err.find("f64 (kept as f32: rounded)"), std::string::npos) << r64.err;
  const BrickStoreSource store64(out64);
  EXPECT_EQ(store64.volume().data_type, DataType::f64);
  const double last = double(e.x * e.y * e.z - 1) * 0.1 - 3.0;  // the largest value written
  EXPECT_EQ(store64.volume().data_range(0), (ValueRange{-3.0, double(float(last))}));
}

// A bad invocation: non-zero exit, exactly one line on stderr containing `needle`, and nothing
// left in the directory (no output, no temporary file).
void expect_clean_failure(const std::string& args, const std::string& needle,
                          const std::string& input_file = "") {
  TempDir dir;
  if (!input_file.empty()) {
    resoct::test::write_bytes(dir.file(input_file), std::vector<std::uint8_t>(100, 1));
  }
  std::string expanded = args;
  for (std::size_t at; (at = expanded.find("@DIR@")) != std::string::npos;) {
    expanded.replace(at, 5, dir.path().string());
  }
  std::string want = needle;
  for (std::size_t at; (at = want.find("@DIR@")) != std::string::npos;) {
    want.replace(at, 5, dir.path().string());
  }
  const ToolRun r = run(dir, RESOCT_CONVERT, expanded);
  EXPECT_NE(r.exit_code, 0) << args;
  EXPECT_EQ(line_count(r.err), 1u) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(want), std::string::npos) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("resoct-convert: error", 0), 0u) << r.err;
  std::vector<std::string> left = dir.entries();
  std::erase(left, input_file);
  EXPECT_TRUE(left.empty()) << args << ": left " << left.front();
}

TEST(Tools, ConvertBadInputFailsCleanly) {
  expect_clean_failure("@DIR@/missing.raw @DIR@/o.rbs --dims 4x4x4 --type u8", "@DIR@/missing.raw");
  // 100 bytes cannot hold 8x8x8 u8 (512 bytes): the message names the file and both sizes.
  expect_clean_failure("@DIR@/short.raw @DIR@/o.rbs --dims 8x8x8 --type u8", "@DIR@/short.raw",
                       "short.raw");
  expect_clean_failure("@DIR@/short.raw @DIR@/o.rbs --dims 8x8x8 --type u8", "512", "short.raw");
  expect_clean_failure("@DIR@/short.raw @DIR@/o.rbs --dims 8x8x8 --type u8", "100 bytes",
                       "short.raw");
  expect_clean_failure("procedural:nosuchvolume:32x32x32 @DIR@/o.rbs", "nosuchvolume");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/o.rbs --brick 2", "--brick");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/o.rbs --codec foo", "--codec");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/o.rbs --codec zstd --level 99", "--level");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/o.rbs --halo 7", "--halo");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/o.rbs --metadata-block 12",
                       "--metadata-block");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/no/such/dir/o.rbs",
                       "@DIR@/no/such/dir/o.rbs");
  expect_clean_failure("procedural:tubes:32x32x32 @DIR@/o.rbs --dims 4x4x4", "--dims");
  expect_clean_failure("@DIR@/in.raw @DIR@/o.rbs --type u8", "--dims", "in.raw");
  expect_clean_failure("@DIR@/in.raw @DIR@/o.rbs --dims 4x4 --type u8", "--dims", "in.raw");
  expect_clean_failure("@DIR@/in.raw @DIR@/o.rbs --dims 4x4x4 --type u12", "--type", "in.raw");
  expect_clean_failure("@DIR@/in.raw @DIR@/o.rbs --dims 4x4x4 --type u8 --endian middle",
                       "--endian", "in.raw");
  expect_clean_failure("@DIR@/in.raw @DIR@/o.rbs --dims 4x4x4 --type u8 --range 5,1", "--range",
                       "in.raw");
  expect_clean_failure("procedural:tubes:32x32x32", "output");  // usage error
}

TEST(Tools, InfoOnACorruptedStoreNamesTheFile) {
  TempDir dir;
  const std::string out = dir.file("c.rbs");
  ASSERT_EQ(run(dir, RESOCT_CONVERT, "procedural:ramp:16x16x16 " + shell_quote(out) + " --brick 8")
                .exit_code,
            0);
  std::vector<std::uint8_t> bytes = resoct::test::read_bytes(out);
  bytes.at(30) ^= 0x40;  // inside the extent field: the header checksum no longer matches
  resoct::test::write_bytes(out, bytes);
  const ToolRun r = run(dir, RESOCT_INFO, shell_quote(out) + " --json");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(out), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;

  const std::string text = dir.file("readme.txt");
  resoct::test::write_bytes(text, {'h', 'e', 'l', 'l', 'o', '\n'});
  const ToolRun t = run(dir, RESOCT_INFO, shell_quote(text));
  EXPECT_NE(t.exit_code, 0);
  EXPECT_EQ(line_count(t.err), 1u) << t.err;
  EXPECT_NE(t.err.find(text), std::string::npos) << t.err;
  const ToolRun m = run(dir, RESOCT_INFO, shell_quote(dir.file("missing.rbs")));
  EXPECT_NE(m.exit_code, 0);
  EXPECT_NE(m.err.find(dir.file("missing.rbs")), std::string::npos) << m.err;
}

}  // namespace
