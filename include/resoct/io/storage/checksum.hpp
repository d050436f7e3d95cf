#pragma once
/// \file
/// CRC-32 (zlib's polynomial) of byte ranges: what the brick store uses to detect corruption.

#include <cstddef>
#include <cstdint>
#include <span>

namespace resoct {

/// CRC-32 as computed by zlib's crc32(), continued from `crc` (0 starts a new checksum), so
/// crc32(b, crc32(a)) == crc32(a followed by b). Spans of any length (also above 4 GiB).
/// Thread-safe (pure function).
std::uint32_t crc32(std::span<const std::byte> data, std::uint32_t crc = 0) noexcept;

}  // namespace resoct
