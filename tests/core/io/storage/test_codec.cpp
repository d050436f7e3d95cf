// LZ4/zstd wrappers and CRC-32: round trips, the documented level ranges, and the error class of
// each kind of bad input.

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "resoct/io/storage/checksum.hpp"
#include "resoct/io/storage/codec.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

std::vector<std::byte> sample(std::size_t n, bool noisy, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::byte> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[i] = noisy ? std::byte(rng() & 0xFFu) : std::byte((i / 97) & 0xFFu);
  }
  return v;
}

std::span<const std::byte> bytes_of(const std::string& s) {
  return std::as_bytes(std::span<const char>(s.data(), s.size()));
}

TEST(Checksum, MatchesTheStandardCrc32CheckValueAndChains) {
  // The CRC-32 (ISO-HDLC) check value of "123456789" is 0xCBF43926.
  EXPECT_EQ(crc32(bytes_of("123456789")), 0xCBF43926u);
  EXPECT_EQ(crc32(bytes_of("")), 0u);
  EXPECT_EQ(crc32(bytes_of("6789"), crc32(bytes_of("12345"))), 0xCBF43926u);
  EXPECT_NE(crc32(bytes_of("123456788")), 0xCBF43926u);
}

TEST(Codec, NamesParseBack) {
  for (const Codec c : {Codec::lz4, Codec::zstd}) EXPECT_EQ(parse_codec(to_string(c)), c);
  EXPECT_FALSE(parse_codec("gzip").has_value());
}

TEST(Codec, RoundTripsAtSeveralLevels) {
  const std::vector<std::pair<Codec, int>> cases = {
      {Codec::lz4, 0},  {Codec::lz4, -8}, {Codec::lz4, 4},   {Codec::lz4, 12},
      {Codec::zstd, 0}, {Codec::zstd, 1}, {Codec::zstd, 19}, {Codec::zstd, -5}};
  for (const auto& [codec, level] : cases) {
    for (const bool noisy : {false, true}) {
      const std::vector<std::byte> in = sample(50000, noisy, 7);
      const std::vector<std::byte> packed = compress(codec, level, in);
      EXPECT_LE(packed.size(), compress_bound(codec, in.size()));
      if (!noisy) {
        EXPECT_LT(packed.size(), in.size() / 10) << to_string(codec) << level;
      }
      std::vector<std::byte> out(in.size());
      decompress_exact(codec, packed, out, "mem", 0);
      EXPECT_EQ(out, in) << to_string(codec) << " level " << level;
    }
  }
}

TEST(Codec, LevelsOutsideTheRangeAreRejected) {
  const std::vector<std::byte> in = sample(100, false, 1);
  EXPECT_RESOCT_ERROR(compress(Codec::lz4, 13, in), ErrorCode::invalid_argument, "level");
  EXPECT_RESOCT_ERROR(compress(Codec::zstd, 1000, in), ErrorCode::invalid_argument, "level");
  EXPECT_RESOCT_ERROR(validate_codec_level(Codec(9), 0), ErrorCode::invalid_argument, "codec");
}

TEST(Codec, WrongSizeAndGarbageHaveDistinctCodes) {
  const std::vector<std::byte> in = sample(4096, false, 3);
  for (const Codec c : {Codec::lz4, Codec::zstd}) {
    const std::vector<std::byte> packed = compress(c, 0, in);
    std::vector<std::byte> bigger(in.size() + 1);
    EXPECT_RESOCT_ERROR(decompress_exact(c, packed, bigger, "f.rbs", 77), ErrorCode::size_mismatch,
                        "f.rbs: offset 77");
    std::vector<std::byte> garbage(300, std::byte{0xFF});
    std::vector<std::byte> out(in.size());
    EXPECT_RESOCT_ERROR(decompress_exact(c, garbage, out, "f.rbs", 5), ErrorCode::decompress_failed,
                        "f.rbs: offset 5");
    // Cut-off stream: the codec must refuse it rather than read past the end.
    const std::span<const std::byte> cut = std::span(packed).first(packed.size() / 2);
    try {
      decompress_exact(c, cut, out, "f.rbs", 9);
      ADD_FAILURE() << "decoded a cut-off " << to_string(c) << " stream";
    } catch (const Error& e) {
      EXPECT_TRUE(e.code() == ErrorCode::decompress_failed || e.code() == ErrorCode::size_mismatch)
          << e.what();
    }
  }
  // zstd announces its size in the frame header: a smaller target is a size mismatch.
  const std::vector<std::byte> packed = compress(Codec::zstd, 0, in);
  std::vector<std::byte> smaller(in.size() - 1);
  EXPECT_RESOCT_ERROR(decompress_exact(Codec::zstd, packed, smaller, "f.rbs", 1),
                      ErrorCode::size_mismatch, "announces");
}

}  // namespace
