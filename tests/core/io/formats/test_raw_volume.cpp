#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/io/formats/raw_volume.hpp"
#include "support/expect_error.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::TempDir;

namespace {

// Values exactly representable in the type, drawn from a seeded RNG; f32 includes negatives,
// fractions and one NaN so that byte swapping of every byte position is exercised.
std::vector<double> make_values(std::size_t n, VoxelType t, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (t == VoxelType::u8) v[i] = double(rng() % 256);
    if (t == VoxelType::u16) v[i] = double(rng() % 65536);
    if (t == VoxelType::f32) v[i] = double(float(int(rng() % 200001) - 100000) / 64.0f);
  }
  if (t == VoxelType::f32 && n > 3) v[3] = std::numeric_limits<double>::quiet_NaN();
  return v;
}

// Encodes one value by shifts (independent of the host byte order and of the code under test).
void encode(std::vector<std::uint8_t>& out, double value, VoxelType t, Endian e) {
  std::uint32_t bits = 0;
  if (t == VoxelType::f32) {
    bits = std::bit_cast<std::uint32_t>(float(value));
  } else {
    bits = std::uint32_t(value);
  }
  const int width = int(voxel_size(t));
  for (int i = 0; i < width; ++i) {
    const int shift = e == Endian::little ? 8 * i : 8 * (width - 1 - i);
    out.push_back(std::uint8_t(bits >> shift));
  }
}

struct RawCase {
  VoxelType type;
  Endian endian;
  std::uint64_t offset;
};

void PrintTo(const RawCase& c, std::ostream* os) {
  *os << to_string(c.type) << " " << to_string(c.endian) << " offset " << c.offset;
}

std::string case_name(const ::testing::TestParamInfo<RawCase>& info) {
  return std::string(to_string(info.param.type)) + "_" + std::string(to_string(info.param.endian)) +
         "_off" + std::to_string(info.param.offset);
}

class RawRoundTrip : public ::testing::TestWithParam<RawCase> {};

TEST_P(RawRoundTrip, VoxelsMatchWrittenValues) {
  const RawCase c = GetParam();
  const glm::u64vec3 extent{7, 5, 3};
  const std::uint32_t channels = 2;
  const std::size_t n = std::size_t(extent.x * extent.y * extent.z);
  std::vector<std::vector<double>> values;
  std::vector<std::uint8_t> file(std::size_t(c.offset), 0xAB);  // header junk
  for (std::uint32_t ch = 0; ch < channels; ++ch) {
    values.push_back(make_values(n, c.type, 100 + ch));
    for (double v : values.back()) encode(file, v, c.type, c.endian);
  }
  file.push_back(0x5A);  // trailing bytes after the voxels are ignored
  TempDir dir;
  const std::string path = dir.file("vol.raw");
  resoct::test::write_bytes(path, file);

  RawVolumeOptions o;
  o.extent = extent;
  o.type = c.type;
  o.endian = c.endian;
  o.channels = channels;
  o.offset = c.offset;
  o.spacing = {0.5, 1.0, 2.5};
  DenseVolume copy;
  {
    const DenseVolume vol = open_raw_volume(path, o);
    EXPECT_EQ(vol.desc().extent, extent);
    EXPECT_EQ(vol.desc().channels, channels);
    EXPECT_EQ(vol.desc().type, c.type);
    EXPECT_EQ(vol.desc().spacing, glm::dvec3(0.5, 1.0, 2.5));
    copy = vol;  // the copy must keep the mapping alive after `vol` is gone
  }
  for (std::uint32_t ch = 0; ch < channels; ++ch) {
    std::size_t i = 0;
    for (std::uint64_t z = 0; z < extent.z; ++z)
      for (std::uint64_t y = 0; y < extent.y; ++y)
        for (std::uint64_t x = 0; x < extent.x; ++x, ++i) {
          const double want = values[ch][i];
          const double got = copy.value(ch, {x, y, z});
          if (std::isnan(want)) {
            EXPECT_TRUE(std::isnan(got)) << "channel " << ch << " voxel " << i;
          } else {
            ASSERT_EQ(got, want) << "channel " << ch << " voxel " << i;
          }
        }
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllTypes, RawRoundTrip,
    ::testing::Values(RawCase{VoxelType::u8, Endian::little, 0},
                      RawCase{VoxelType::u8, Endian::big, 5000},  // mapping starts past page 0
                      RawCase{VoxelType::u16, Endian::little, 0},
                      RawCase{VoxelType::u16, Endian::little, 13},  // misaligned: copied
                      RawCase{VoxelType::u16, Endian::big, 16},
                      RawCase{VoxelType::f32, Endian::little, 4100},
                      RawCase{VoxelType::f32, Endian::big, 0},
                      RawCase{VoxelType::f32, Endian::big, 7}),
    case_name);

TEST(RawVolume, FeedsAnInMemorySourceLikeOwnedBytes) {
  const glm::u64vec3 extent{20, 12, 9};
  const std::size_t n = std::size_t(extent.x * extent.y * extent.z);
  const std::vector<double> values = make_values(n, VoxelType::u16, 7);
  std::vector<std::uint8_t> file;
  std::vector<std::uint16_t> native;
  for (double v : values) {
    encode(file, v, VoxelType::u16, Endian::big);
    native.push_back(std::uint16_t(v));
  }
  TempDir dir;
  const std::string path = dir.file("big.raw");
  resoct::test::write_bytes(path, file);
  RawVolumeOptions o;
  o.extent = extent;
  o.type = VoxelType::u16;
  o.endian = Endian::big;
  VolumeDesc d;
  d.extent = extent;
  d.type = VoxelType::u16;
  BrickLayout layout;
  layout.brick_size = glm::uvec3(4);
  const InMemorySource raw(open_raw_volume(path, o), layout);
  const InMemorySource ref(DenseVolume::from_values(d, native), layout);
  ASSERT_EQ(raw.hierarchy().level_count(), ref.hierarchy().level_count());
  const std::size_t bytes = layout.padded_voxels() * 2;
  std::vector<std::byte> a(bytes), b(bytes);
  for (std::uint64_t i = 0; i < raw.hierarchy().bricks_per_channel(); ++i) {
    const BrickKey key = raw.hierarchy().key_from_linear(0, i);
    raw.read_brick(key, a);
    ref.read_brick(key, b);
    ASSERT_EQ(std::memcmp(a.data(), b.data(), bytes), 0) << "brick " << i;
  }
}

TEST(RawVolume, TruncatedFileNamesFileAndSizes) {
  TempDir dir;
  const std::string path = dir.file("short.raw");
  // 2 channels of 8x8x4 u16 after a 10-byte header: 10 + 1024 bytes needed, 1033 present.
  resoct::test::write_bytes(path, std::vector<std::uint8_t>(1033, 1));
  RawVolumeOptions o;
  o.extent = {8, 8, 4};
  o.type = VoxelType::u16;
  o.channels = 2;
  o.offset = 10;
  try {
    open_raw_volume(path, o);
    FAIL() << "no error for a truncated file";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::truncated);
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("1033"), std::string::npos) << msg;
    EXPECT_NE(msg.find("1034"), std::string::npos) << msg;
  }
  // One byte more and it opens.
  resoct::test::write_bytes(path, std::vector<std::uint8_t>(1034, 1));
  EXPECT_EQ(open_raw_volume(path, o).value(1, {7, 7, 3}), double(0x0101));
}

TEST(RawVolume, AbsurdParametersAreNamed) {
  TempDir dir;
  const std::string path = dir.file("any.raw");
  resoct::test::write_bytes(path, std::vector<std::uint8_t>(64, 0));
  RawVolumeOptions o;
  o.extent = {4, 4, 4};
  o.extent.y = 0;
  EXPECT_RESOCT_ERROR(open_raw_volume(path, o), ErrorCode::invalid_argument, "extent.y");
  o.extent = {std::uint64_t(1) << 40, std::uint64_t(1) << 40, 4};
  EXPECT_RESOCT_ERROR(open_raw_volume(path, o), ErrorCode::overflow, "64 bits");
  o.extent = {4, 4, 4};
  o.channels = 0;
  EXPECT_RESOCT_ERROR(open_raw_volume(path, o), ErrorCode::invalid_argument, "channels");
  o.channels = 1;
  o.spacing = {1.0, -1.0, 1.0};
  EXPECT_RESOCT_ERROR(open_raw_volume(path, o), ErrorCode::invalid_argument, "spacing.y");
  o.spacing = glm::dvec3(1.0);
  o.offset = std::numeric_limits<std::uint64_t>::max() - 10;
  EXPECT_RESOCT_ERROR(open_raw_volume(path, o), ErrorCode::overflow, "offset");
  o.offset = 0;
  o.ranges = {ValueRange{2.0, 1.0}};
  EXPECT_RESOCT_ERROR(open_raw_volume(path, o), ErrorCode::invalid_argument, "ranges[0]");
  o.ranges.clear();
  EXPECT_EQ(open_raw_volume(path, o).desc().extent, glm::u64vec3(4));
}

TEST(RawVolume, MissingFileAndDirectoryAreIoErrors) {
  TempDir dir;
  RawVolumeOptions o;
  o.extent = {2, 2, 2};
  const std::string missing = dir.file("nope.raw");
  EXPECT_RESOCT_ERROR(open_raw_volume(missing, o), ErrorCode::io, missing);
  EXPECT_RESOCT_ERROR(open_raw_volume(dir.path().string(), o), ErrorCode::io, "not a regular");
}

TEST(RawVolume, EndianNames) {
  EXPECT_EQ(parse_endian("little"), Endian::little);
  EXPECT_EQ(parse_endian("be"), Endian::big);
  EXPECT_FALSE(parse_endian("middle").has_value());
  EXPECT_EQ(to_string(Endian::big), "big");
}

}  // namespace
