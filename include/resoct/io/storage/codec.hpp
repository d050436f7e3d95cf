#pragma once
/// \file
/// Thin wrappers over LZ4 and zstd, the two codecs the brick store compresses payloads with.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace resoct {

/// A lossless byte codec. The numeric values are part of the brick store format.
enum class Codec : std::uint8_t {
  lz4 = 0,   ///< fast to decode; level 0 = LZ4 default, 1..12 = LZ4-HC level, < 0 = acceleration
  zstd = 1,  ///< better ratio; level 0 = zstd default (3), otherwise ZSTD_minCLevel..maxCLevel
};

/// "lz4", "zstd".
std::string_view to_string(Codec c) noexcept;
/// Parses "lz4" or "zstd"; empty on anything else.
std::optional<Codec> parse_codec(std::string_view s) noexcept;

/// Throws invalid_parameter("level", ...) when `level` is outside the codec's range (see Codec).
void validate_codec_level(Codec c, int level);

/// Largest compressed size of `n` input bytes. Throws invalid_parameter when the codec cannot
/// take that many bytes in one block (LZ4 stops just below 2 GiB).
std::size_t compress_bound(Codec c, std::size_t n);

/// Compresses `in` and returns the compressed bytes. Thread-safe: each thread reuses its own
/// codec context. Throws invalid_parameter for a bad level or an input too large for the codec.
std::vector<std::byte> compress(Codec c, int level, std::span<const std::byte> in);

/// Decompresses `in` into exactly `out.size()` bytes. Throws
/// file_error(size_mismatch, file, offset, ...) when the data decodes to another size and
/// file_error(decompress_failed, ...) when the codec rejects it; `file` and `offset` only name
/// where `in` came from. Thread-safe.
void decompress_exact(Codec c, std::span<const std::byte> in, std::span<std::byte> out,
                      std::string_view file, std::uint64_t offset);

}  // namespace resoct
