// The brick store's errors section (docs/brick-store-format.md "Errors section"): a store written
// with StoreWriteOptions::brick_errors answers BrickSource::brick_error from the file, with the
// value the measurement gives; everything else in the file reads back as without it; a damaged
// section is refused at open, naming the file and the offset. Section fields are located from
// the documented layout, not from the store's own encoder.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <zstd.h>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/sources/brick_error.hpp"
#include "support/expect_error.hpp"
#include "support/function_source.hpp"

using namespace resoct;
using resoct::test::FunctionSource;
using resoct::test::get_le;
using resoct::test::put_le;
using resoct::test::read_bytes;
using resoct::test::TempDir;
using resoct::test::write_bytes;

namespace {

constexpr std::size_t kFlagBrickErrors = 1u << 2;  // header flag bit 2

// 2 channels, 4 levels of 8³ bricks: smooth ramps with noise, an empty slab, a constant block.
FunctionSource source(VoxelType type = VoxelType::u8) {
  VolumeDesc v;
  v.extent = {40, 33, 24};
  v.channels = 2;
  v.type = type;
  return FunctionSource(v, BrickLayout{glm::uvec3(8), 1},
                        [type](std::uint32_t c, const glm::u64vec3& p) {
                          if (p.z >= 16 && p.y < 8)
                            return 77.0 * (type == VoxelType::f32 ? 0.01 : 1);
                          return test::test_value(type, c, p, glm::u64vec3(40, 33, 24));
                        });
}

std::vector<std::byte> padded(const BrickSource& s, BrickKey key) {
  std::vector<std::byte> out(s.hierarchy().layout().padded_voxels() * voxel_size(s.volume().type));
  s.read_brick(key, out);
  return out;
}

template <class F>
void for_each_key(const BrickHierarchy& h, F&& f) {
  for (std::uint64_t i = 0; i < h.bricks_per_channel() * h.volume().channels; ++i) {
    f(h.key_from_linear(std::uint32_t(i / h.bricks_per_channel()), i % h.bricks_per_channel()));
  }
}

std::string write(const BrickSource& src, const TempDir& dir, const std::string& name,
                  bool errors) {
  StoreWriteOptions o;
  o.brick_errors = errors;
  o.threads = 3;
  const std::string path = dir.file(name);
  write_brick_store(src, path, o);
  return path;
}

// Where the errors section's header fields are (after the ranges; no origin in these stores).
std::size_t error_fields(const std::vector<std::uint8_t>& b) {
  return 184 + 16 * std::size_t(get_le(b, test::layout::channels, 4));
}

TEST(BrickStoreErrors, StoredErrorsAreTheMeasuredOnes) {
  for (VoxelType type : {VoxelType::u8, VoxelType::f32}) {
    const FunctionSource src = source(type);
    const TempDir dir;
    const BrickStoreSource store(write(src, dir, "e.rbs", true));
    ASSERT_TRUE(store.stats().brick_errors);
    const BrickHierarchy& h = src.hierarchy();
    std::vector<double> max_error(h.level_count(), 0.0);
    std::size_t nonzero = 0;
    for_each_key(h, [&](BrickKey key) {
      const std::vector<std::byte> voxels = padded(src, key);
      const float want =
          key.level() == 0 ? 0.0f : brick_error_to_float(measure_brick_error(src, key, voxels));
      const double got = store.brick_error(key, voxels);
      ASSERT_EQ(got, double(want)) << "level " << key.level() << " channel " << key.channel();
      max_error[key.level()] = std::max(max_error[key.level()], double(want));
      nonzero += want > 0.0f;
    });
    EXPECT_GT(nonzero, 10u);  // the data is not constant: the test compares real measurements
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      EXPECT_EQ(store.stats().levels[l].max_error, max_error[l]) << "level " << l;
    }
    EXPECT_GT(store.stats().total().mean_error, 0.0);
  }
}

TEST(BrickStoreErrors, EverythingElseReadsBackAsWithoutThem) {
  const FunctionSource src = source();
  const TempDir dir;
  const std::string with = write(src, dir, "with.rbs", true);
  const std::string without = write(src, dir, "without.rbs", false);
  const BrickStoreSource a(with), b(without);
  EXPECT_FALSE(b.stats().brick_errors);
  // Only the flag, the 24 bytes of section fields and the section itself differ in size.
  const std::vector<std::uint8_t> fw = read_bytes(with), fo = read_bytes(without);
  EXPECT_EQ(get_le(fw, test::layout::flags, 4),
            get_le(fo, test::layout::flags, 4) | kFlagBrickErrors);
  EXPECT_EQ(get_le(fw, test::layout::header_size, 4),
            get_le(fo, test::layout::header_size, 4) + 24);
  for_each_key(src.hierarchy(), [&](BrickKey key) {
    ASSERT_EQ(padded(a, key), padded(b, key));
    ASSERT_EQ(a.brick_meta(key), b.brick_meta(key));
  });
  const Box3 region{{3, 0, 5}, {37, 30, 24}};
  EXPECT_EQ(a.region_meta(1, region), b.region_meta(1, region));
  // A store without errors measures them (the default BrickSource::brick_error).
  const BrickKey key(1, 1, {1, 1, 0});
  const std::vector<std::byte> voxels = padded(b, key);
  EXPECT_EQ(b.brick_error(key, voxels), measure_brick_error(b, key, voxels));
  EXPECT_EQ(a.brick_error(key, voxels), double(brick_error_to_float(b.brick_error(key, voxels))));
}

TEST(BrickStoreErrors, AskingForAKeyOrBufferTheStoreCannotHaveIsRefused) {
  const FunctionSource src = source();
  const TempDir dir;
  const BrickStoreSource store(write(src, dir, "e.rbs", true));
  std::vector<std::byte> small(3);
  EXPECT_RESOCT_ERROR(store.brick_error(BrickKey(1, 0, {0, 0, 0}), small),
                      ErrorCode::invalid_argument, "out");
  const std::vector<std::byte> voxels = padded(src, BrickKey(1, 0, {0, 0, 0}));
  EXPECT_RESOCT_ERROR(store.brick_error(BrickKey(1, 2, {0, 0, 0}), voxels), ErrorCode::out_of_range,
                      "e.rbs");
  EXPECT_RESOCT_ERROR(store.brick_error(BrickKey(9, 0, {0, 0, 0}), voxels), ErrorCode::out_of_range,
                      "e.rbs");
}

// Rewrites the errors section with `raw` (f32 values), placed at the end of the file, and fixes
// the section's fields and the header CRC.
void replace_section(std::vector<std::uint8_t>& b, const std::vector<float>& values) {
  std::vector<std::uint8_t> raw(values.size() * 4);
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::uint32_t bits;
    std::memcpy(&bits, &values[i], 4);
    put_le(raw, 4 * i, bits, 4);
  }
  std::vector<std::uint8_t> packed(ZSTD_compressBound(raw.size()));
  packed.resize(ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), 1));
  const std::size_t at = b.size();
  b.insert(b.end(), packed.begin(), packed.end());
  const std::size_t f = error_fields(b);
  put_le(b, f, at, 8);
  put_le(b, f + 8, packed.size(), 8);
  put_le(b, f + 16, test::zlib_crc(b, at, packed.size()), 4);
  test::fix_header_crc(b);
}

std::vector<float> section_values(const std::vector<std::uint8_t>& b) {
  const std::size_t f = error_fields(b);
  const std::size_t at = std::size_t(get_le(b, f, 8)), size = std::size_t(get_le(b, f + 8, 8));
  const std::size_t entries = std::size_t(get_le(b, test::layout::index_size, 8)) / 40;
  std::vector<std::uint8_t> raw(entries * 4);
  EXPECT_EQ(ZSTD_decompress(raw.data(), raw.size(), b.data() + at, size), raw.size());
  std::vector<float> v(entries);
  for (std::size_t i = 0; i < entries; ++i) {
    const std::uint32_t bits = std::uint32_t(get_le(raw, 4 * i, 4));
    std::memcpy(&v[i], &bits, 4);
  }
  return v;
}

TEST(BrickStoreErrors, ADamagedSectionIsRefusedNamingTheOffset) {
  const FunctionSource src = source();
  const TempDir dir;
  const std::string path = write(src, dir, "e.rbs", true);
  const std::vector<std::uint8_t> good = read_bytes(path);
  const std::size_t f = error_fields(good);
  const std::size_t at = std::size_t(get_le(good, f, 8));
  const std::size_t size = std::size_t(get_le(good, f + 8, 8));
  ASSERT_EQ(at + size, good.size());  // the writer puts it last
  // The values the writer stored are the store's answers.
  const std::vector<float> values = section_values(good);
  {
    const BrickStoreSource store(path);
    const BrickKey key =
        src.hierarchy().key_from_linear(1, src.hierarchy().level(1).first_brick + 1);
    EXPECT_EQ(store.brick_error(key, padded(src, key)),
              double(values[src.hierarchy().bricks_per_channel() +
                            src.hierarchy().level(1).first_brick + 1]));
  }
  const std::string bad = dir.file("bad.rbs");
  auto refused = [&](std::vector<std::uint8_t> b, ErrorCode code, const std::string& what) {
    write_bytes(bad, b);
    EXPECT_RESOCT_ERROR(BrickStoreSource{bad}, code, what);
  };
  {  // a flipped byte in the section
    std::vector<std::uint8_t> b = good;
    b[at + size / 2] ^= 0x40;
    refused(b, ErrorCode::checksum_mismatch, "offset " + std::to_string(at) + ": errors section");
  }
  // cut inside the section
  refused(std::vector<std::uint8_t>(good.begin(), good.end() - 1), ErrorCode::truncated, "errors");
  {  // the section overlapping the metadata
    std::vector<std::uint8_t> b = good;
    put_le(b, f, get_le(b, test::layout::metadata_offset, 8), 8);
    test::fix_header_crc(b);
    refused(b, ErrorCode::corrupt, "overlap");
  }
  {  // the reserved word
    std::vector<std::uint8_t> b = good;
    put_le(b, f + 20, 1, 4);
    test::fix_header_crc(b);
    refused(b, ErrorCode::corrupt, "offset " + std::to_string(f + 20));
  }
  {  // an impossible compressed size
    std::vector<std::uint8_t> b = good;
    put_le(b, f + 8, 0, 8);
    test::fix_header_crc(b);
    refused(b, ErrorCode::corrupt, "offset " + std::to_string(f + 8));
  }
  for (float v : {-0.25f, 1.5f, std::numeric_limits<float>::quiet_NaN(),
                  std::numeric_limits<float>::infinity()}) {  // values outside [0, 1]
    std::vector<std::uint8_t> b = good;
    std::vector<float> vals = values;
    vals[7] = v;
    replace_section(b, vals);
    refused(b, ErrorCode::corrupt, "brick index entry 7");
  }
  {  // a section of the wrong raw size
    std::vector<std::uint8_t> b = good;
    std::vector<float> vals = values;
    vals.pop_back();
    replace_section(b, vals);
    refused(b, ErrorCode::size_mismatch, "offset " + std::to_string(good.size()));
  }
  {  // the flag without the fields: the header size no longer matches
    std::vector<std::uint8_t> b = read_bytes(write(src, dir, "plain.rbs", false));
    put_le(b, test::layout::flags, get_le(b, test::layout::flags, 4) | kFlagBrickErrors, 4);
    test::fix_header_crc(b);
    refused(b, ErrorCode::corrupt, "header size");
  }
  {  // a valid section with a value no measurement gives: the store answers from the file
    std::vector<std::uint8_t> b = good;
    std::vector<float> vals = values;
    const BrickHierarchy& h = src.hierarchy();
    const std::uint64_t i = h.bricks_per_channel() + h.level(1).first_brick + 1;
    vals[std::size_t(i)] = 0.375f;
    replace_section(b, vals);
    write_bytes(bad, b);
    const BrickStoreSource store(bad);
    const BrickKey key = h.key_from_linear(1, h.level(1).first_brick + 1);
    const std::vector<std::byte> voxels = padded(src, key);
    ASSERT_NE(measure_brick_error(src, key, voxels), 0.375);
    EXPECT_EQ(store.brick_error(key, voxels), 0.375);
  }
  // And the intact file still opens (the copies above did not alias it).
  write_bytes(bad, good);
  EXPECT_NO_THROW(BrickStoreSource{bad});
}

TEST(BrickStoreErrors, AStoreConvertedFromAStoreKeepsItsErrors) {
  const FunctionSource src = source();
  const TempDir dir;
  const BrickStoreSource first(write(src, dir, "first.rbs", true));
  // The second writer asks the first store, which answers from its file.
  const BrickStoreSource second(write(first, dir, "second.rbs", true));
  for_each_key(src.hierarchy(), [&](BrickKey key) {
    const std::vector<std::byte> voxels = padded(first, key);
    ASSERT_EQ(second.brick_error(key, voxels), first.brick_error(key, voxels));
  });
  EXPECT_EQ(read_bytes(dir.file("first.rbs")), read_bytes(dir.file("second.rbs")));
}

}  // namespace
