// Damaged brick stores: truncation and byte flips in every section, and one hand-made file per
// failure class. Opening must throw resoct::Error naming the file, or (damage inside a payload)
// opening succeeds and exactly the damaged brick fails to read. Never a crash.

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <set>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/storage/codec.hpp"
#include "support/expect_error.hpp"
#include "support/function_source.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::FunctionSource;
using resoct::test::TempDir;
namespace lay = resoct::test::layout;
using test::get_le;
using test::put_le;

namespace {

struct Sections {
  std::size_t header = 0, payload = 0, payload_size = 0, index = 0, index_size = 0, meta = 0,
              meta_size = 0;
};

Sections sections_of(const std::vector<std::uint8_t>& b) {
  Sections s;
  s.header = std::size_t(get_le(b, lay::header_size, 4));
  s.payload = std::size_t(get_le(b, lay::payload_offset, 8));
  s.payload_size = std::size_t(get_le(b, lay::payload_size, 8));
  s.index = std::size_t(get_le(b, lay::index_offset, 8));
  s.index_size = std::size_t(get_le(b, lay::index_size, 8));
  s.meta = std::size_t(get_le(b, lay::metadata_offset, 8));
  s.meta_size = std::size_t(get_le(b, lay::metadata_size, 8));
  return s;
}

class CorruptStore : public ::testing::TestWithParam<Codec> {
 protected:
  void SetUp() override {
    VolumeDesc v;
    v.extent = {40, 33, 17};
    v.channels = 2;
    v.type = VoxelType::u16;
    src_.emplace(v, BrickLayout{glm::uvec3(8), 1}, [](std::uint32_t c, const glm::u64vec3& p) {
      return test::test_value(VoxelType::u16, c, p, {40, 33, 17});
    });
    good_ = dir_.file("good.rbs");
    bad_ = dir_.file("bad.rbs");
    write_brick_store(*src_, good_, StoreWriteOptions{GetParam()});
    bytes_ = test::read_bytes(good_);
    sec_ = sections_of(bytes_);
    ASSERT_EQ(sec_.payload, sec_.header);
    ASSERT_EQ(sec_.index, sec_.payload + sec_.payload_size);
    ASSERT_EQ(sec_.meta, sec_.index + sec_.index_size);
    ASSERT_EQ(bytes_.size(), sec_.meta + sec_.meta_size);
  }

  std::vector<BrickKey> keys() const {
    std::vector<BrickKey> out;
    const BrickHierarchy& h = src_->hierarchy();
    for (std::uint32_t c = 0; c < 2; ++c) {
      for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i)
        out.push_back(h.key_from_linear(c, i));
    }
    return out;
  }
  std::vector<std::byte> read(const BrickSource& s, BrickKey k) const {
    std::vector<std::byte> b(s.hierarchy().layout().padded_voxels() * 2);
    s.read_brick(k, b);
    return b;
  }
  // Index entry position of a brick (channel-major, then linear index).
  std::size_t entry_at(BrickKey k) const {
    const BrickHierarchy& h = src_->hierarchy();
    return sec_.index + std::size_t(k.channel() * h.bricks_per_channel() +
                                    h.linear_index(k.level(), k.brick())) *
                            lay::entry_size;
  }
  bool stored(BrickKey k) const {
    return (get_le(bytes_, entry_at(k) + lay::entry_flags, 4) & 1u) != 0;
  }
  // The stored brick with the largest payload (room to put other data in its place).
  BrickKey largest_payload() const {
    BrickKey best;
    std::uint64_t size = 0;
    for (const BrickKey k : keys()) {
      const std::uint64_t s = get_le(bytes_, entry_at(k) + lay::entry_size_field, 4);
      if (stored(k) && s > size) {
        size = s;
        best = k;
      }
    }
    return best;
  }

  TempDir dir_;
  std::optional<FunctionSource> src_;
  std::string good_, bad_;
  std::vector<std::uint8_t> bytes_;
  Sections sec_;
};

TEST_P(CorruptStore, TruncationAnywhereIsReportedAsTruncated) {
  const Sections& s = sec_;
  const std::vector<std::size_t> cuts = {0,
                                         3,
                                         8,
                                         12,
                                         15,
                                         16,
                                         100,
                                         s.header - 1,
                                         s.header,
                                         s.header + 1,
                                         s.payload + s.payload_size / 3,
                                         s.payload + s.payload_size / 2,
                                         s.index - 1,
                                         s.index,
                                         s.index + 1,
                                         s.index + s.index_size / 2,
                                         s.meta - 1,
                                         s.meta,
                                         s.meta + s.meta_size / 2,
                                         bytes_.size() - 1};
  for (const std::size_t cut : cuts) {
    std::vector<std::uint8_t> b(bytes_.begin(), bytes_.begin() + std::ptrdiff_t(cut));
    test::write_bytes(bad_, b);
    EXPECT_RESOCT_ERROR(BrickStoreSource{bad_}, ErrorCode::truncated, bad_) << "cut at " << cut;
  }
}

TEST_P(CorruptStore, EveryHeaderByteFlipIsCaughtAtOpen) {
  for (std::size_t at = 0; at < sec_.header; ++at) {
    std::vector<std::uint8_t> b = bytes_;
    b[at] ^= 0x5A;
    test::write_bytes(bad_, b);
    if (at < 8) {
      EXPECT_RESOCT_ERROR(BrickStoreSource{bad_}, ErrorCode::bad_magic, bad_) << at;
    } else if (at >= lay::header_size && at < lay::header_size + 4) {
      // A changed header size moves the checksum or the end of the header.
      try {
        BrickStoreSource s(bad_);
        ADD_FAILURE() << "opened a store with a damaged header size";
      } catch (const Error& e) {
        EXPECT_TRUE(e.code() == ErrorCode::checksum_mismatch || e.code() == ErrorCode::truncated ||
                    e.code() == ErrorCode::corrupt)
            << e.what();
        EXPECT_NE(std::string(e.what()).find(bad_), std::string::npos);
      }
    } else {
      EXPECT_RESOCT_ERROR(BrickStoreSource{bad_}, ErrorCode::checksum_mismatch, bad_) << at;
    }
  }
}

TEST_P(CorruptStore, IndexAndMetadataByteFlipsFailTheirChecksums) {
  for (int i = 0; i < 24; ++i) {
    const std::size_t at = sec_.index + (sec_.index_size - 1) * std::size_t(i) / 23;
    std::vector<std::uint8_t> b = bytes_;
    b[at] ^= 0x01;
    test::write_bytes(bad_, b);
    EXPECT_RESOCT_ERROR(BrickStoreSource{bad_}, ErrorCode::checksum_mismatch,
                        bad_ + ": offset " + std::to_string(sec_.index))
        << at;
  }
  for (int i = 0; i < 12; ++i) {
    const std::size_t at = sec_.meta + (sec_.meta_size - 1) * std::size_t(i) / 11;
    std::vector<std::uint8_t> b = bytes_;
    b[at] ^= 0x80;
    test::write_bytes(bad_, b);
    EXPECT_RESOCT_ERROR(BrickStoreSource{bad_}, ErrorCode::checksum_mismatch,
                        bad_ + ": offset " + std::to_string(sec_.meta))
        << at;
  }
}

TEST_P(CorruptStore, PayloadByteFlipBreaksOnlyThatBrick) {
  const std::vector<BrickKey> all = keys();
  std::vector<std::vector<std::byte>> want;
  for (const BrickKey k : all) want.push_back(read(*src_, k));
  for (int i = 0; i < 24; ++i) {
    const std::size_t at = sec_.payload + (sec_.payload_size - 1) * std::size_t(i) / 23;
    std::vector<std::uint8_t> b = bytes_;
    b[at] ^= 0x10;
    test::write_bytes(bad_, b);
    const BrickStoreSource store(bad_);  // payloads are verified on read, not on open
    int broken = 0;
    for (std::size_t k = 0; k < all.size(); ++k) {
      const std::size_t e = entry_at(all[k]);
      const std::size_t off = std::size_t(get_le(bytes_, e + lay::entry_offset, 8));
      const std::size_t size = std::size_t(get_le(bytes_, e + lay::entry_size_field, 4));
      if (stored(all[k]) && at >= off && at < off + size) {
        ++broken;
        EXPECT_RESOCT_ERROR(read(store, all[k]), ErrorCode::checksum_mismatch,
                            bad_ + ": offset " + std::to_string(off));
      } else {
        EXPECT_EQ(read(store, all[k]), want[k]);
      }
    }
    EXPECT_EQ(broken, 1) << "flip at " << at << " must land in exactly one payload";
  }
}

TEST_P(CorruptStore, EachFailureClassHasItsOwnCode) {
  auto expect_open = [&](std::vector<std::uint8_t> b, ErrorCode code, const std::string& where) {
    test::write_bytes(bad_, b);
    EXPECT_RESOCT_ERROR(BrickStoreSource{bad_}, code, bad_ + ": offset " + where);
  };
  {  // foreign file
    std::vector<std::uint8_t> b = bytes_;
    b[1] = 'X';
    expect_open(b, ErrorCode::bad_magic, "1");
  }
  {  // a newer version with a valid header checksum
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::version, 2, 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::unsupported_version, "8");
  }
  {  // unknown feature flag
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::flags, 1u << 7, 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::unsupported, "16");
  }
  {  // a file value type the stored voxel type cannot hold (i16 is kept as u16), and no type
    std::vector<std::uint8_t> b = bytes_;
    const bool u16 = get_le(b, 20, 4) == std::uint32_t(VoxelType::u16);
    put_le(b, lay::data_type, std::uint32_t(u16 ? DataType::i8 : DataType::i16), 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::corrupt, "180");
    put_le(b, lay::data_type, 99, 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::corrupt, "180");
  }
  {  // voxel count overflowing 64 bits
    std::vector<std::uint8_t> b = bytes_;
    for (int a = 0; a < 3; ++a) put_le(b, lay::extent + 8 * a, 1ull << 32, 8);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::overflow, "24");
  }
  {  // huge but representable extent: rejected from the header alone, nothing allocated
    std::vector<std::uint8_t> b = bytes_;
    for (int a = 0; a < 3; ++a) put_le(b, lay::extent + 8 * a, 1ull << 20, 8);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::corrupt, "");
  }
  {  // zero extent
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::extent + 8, 0, 8);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::corrupt, "32");
  }
  {  // absurd brick size
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::brick_size, 2, 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::corrupt, "76");
  }
  {  // absurd channel count
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::channels, 100000, 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::corrupt, "72");
  }
  {  // section claimed past the end of the file
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::metadata_size, 1ull << 40, 8);
    test::fix_header_crc(b);
    EXPECT_RESOCT_ERROR((test::write_bytes(bad_, b), BrickStoreSource{bad_}), ErrorCode::truncated,
                        bad_);
  }
  {  // index entry pointing past the end of the file
    std::vector<std::uint8_t> b = bytes_;
    const std::size_t e = entry_at(largest_payload());
    put_le(b, e + lay::entry_offset, bytes_.size() + 100, 8);
    test::fix_index_crc(b);
    expect_open(b, ErrorCode::out_of_range, std::to_string(e));
  }
  {  // metadata checksum mismatch without damage elsewhere
    std::vector<std::uint8_t> b = bytes_;
    put_le(b, lay::metadata_crc, get_le(b, lay::metadata_crc, 4) ^ 1u, 4);
    test::fix_header_crc(b);
    expect_open(b, ErrorCode::checksum_mismatch, std::to_string(sec_.meta));
  }
  const BrickKey victim = largest_payload();
  const std::size_t e = entry_at(victim);
  const std::size_t off = std::size_t(get_le(bytes_, e + lay::entry_offset, 8));
  const std::size_t size = std::size_t(get_le(bytes_, e + lay::entry_size_field, 4));
  const std::string at = bad_ + ": offset " + std::to_string(off);
  {  // payload the codec rejects, with every checksum fixed so the codec sees it
    std::vector<std::uint8_t> b = bytes_;
    std::fill(b.begin() + std::ptrdiff_t(off), b.begin() + std::ptrdiff_t(off + size), 0xFF);
    put_le(b, e + lay::entry_crc, test::zlib_crc(b, off, size), 4);
    test::fix_index_crc(b);
    test::write_bytes(bad_, b);
    const BrickStoreSource store(bad_);
    EXPECT_RESOCT_ERROR(read(store, victim), ErrorCode::decompress_failed, at);
  }
  {  // valid compressed data of the wrong size
    const std::vector<std::byte> half(src_->hierarchy().layout().padded_voxels(), std::byte{7});
    const std::vector<std::byte> packed = compress(GetParam(), 0, half);
    ASSERT_LT(packed.size(), size);
    std::vector<std::uint8_t> b = bytes_;
    std::memcpy(b.data() + off, packed.data(), packed.size());
    put_le(b, e + lay::entry_size_field, packed.size(), 4);
    put_le(b, e + lay::entry_crc, test::zlib_crc(b, off, packed.size()), 4);
    test::fix_index_crc(b);
    test::write_bytes(bad_, b);
    const BrickStoreSource store(bad_);
    EXPECT_RESOCT_ERROR(read(store, victim), ErrorCode::size_mismatch, at);
  }
  EXPECT_RESOCT_ERROR(BrickStoreSource{dir_.file("missing.rbs")}, ErrorCode::io,
                      dir_.file("missing.rbs"));
  EXPECT_RESOCT_ERROR(BrickStoreSource{dir_.path().string()}, ErrorCode::io, dir_.path().string());
  // The untouched original still opens: every case above failed for its own reason.
  EXPECT_NO_THROW(BrickStoreSource{good_});
}

INSTANTIATE_TEST_SUITE_P(Codecs, CorruptStore, ::testing::Values(Codec::lz4, Codec::zstd),
                         [](const auto& p) { return std::string(to_string(p.param)); });

}  // namespace

namespace {

// Random values in header fields and index entries with every checksum recomputed, so that the
// field validation itself (not the CRC) must catch them. Opening and reading must either work or
// throw resoct::Error naming the file; nothing may crash or allocate absurdly.
TEST_P(CorruptStore, RandomFieldsWithValidChecksumsNeverCrash) {
  std::mt19937_64 rng(2024);
  // clang-format off
  const std::vector<std::pair<std::size_t, int>> header_fields = {
      {lay::flags, 4}, {20, 4}, {lay::extent, 8}, {lay::extent + 8, 8}, {lay::extent + 16, 8},
      {48, 8}, {lay::channels, 4}, {lay::brick_size, 4}, {lay::brick_size + 8, 4}, {88, 4},
      {92, 4}, {96, 4}, {100, 4}, {104, 4}, {112, 8}, {lay::payload_offset, 8},
      {lay::payload_size, 8}, {lay::index_offset, 8}, {lay::index_size, 8},
      {lay::metadata_offset, 8}, {lay::metadata_size, 8}, {168, 8}, {180, 4}, {184, 8}, {192, 8}};
  // clang-format on
  const std::size_t entries = sec_.index_size / lay::entry_size;
  int opened = 0, rejected = 0;
  for (int round = 0; round < 120; ++round) {
    std::vector<std::uint8_t> b = bytes_;
    if (round % 2 == 0) {
      const auto [at, width] = header_fields[std::size_t(rng() % header_fields.size())];
      // Small values, powers of two and arbitrary bits: the interesting neighbourhoods.
      const std::uint64_t v = round % 6 == 0   ? rng() % 64
                              : round % 6 == 2 ? 1ull << (rng() % 63)
                                               : rng();
      put_le(b, at, v, width);
      test::fix_header_crc(b);
    } else {
      const std::size_t e = sec_.index + std::size_t(rng() % entries) * lay::entry_size;
      const std::size_t field = std::size_t(rng() % 10) * 4;
      put_le(b, e + field, round % 3 == 0 ? rng() % 8 : rng(), 4);
      test::fix_index_crc(b);
    }
    test::write_bytes(bad_, b);
    try {
      const BrickStoreSource store(bad_);
      ++opened;
      const BrickLayout& layout = store.hierarchy().layout();
      ASSERT_LE(layout.padded_voxels(), 1u << 20) << "accepted an altered brick size";
      for (const BrickKey k : keys()) {
        std::vector<std::byte> out(layout.padded_voxels() * voxel_size(store.volume().type));
        try {
          store.read_brick(k, out);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find(bad_), std::string::npos) << e.what();
        }
      }
    } catch (const Error& e) {
      ++rejected;
      EXPECT_NE(std::string(e.what()).find(bad_), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(rejected, 60);  // most random values are impossible and must be refused
  EXPECT_EQ(opened + rejected, 120);
}

}  // namespace
