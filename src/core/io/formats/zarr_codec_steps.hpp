#pragma once
// Decoding steps shared by the zarr v2 chunk decoder and the v3 codec pipeline (internal).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace resoct::detail {

/// Decoded bytes a blosc frame announces; Error(corrupt) naming `location` and offset 0 when
/// the header is not a valid frame of `in.size()` bytes.
std::uint64_t blosc_frame_bytes(std::span<const std::byte> in, std::string_view location);

/// Decodes a blosc frame into exactly `out` (Error(size_mismatch) when the frame holds another
/// size, Error(decompress_failed) when libblosc fails). Thread-safe.
void decode_blosc(std::span<const std::byte> in, std::span<std::byte> out,
                  std::string_view location);

/// Reverses the byte order of each `width`-byte element of `v`.
void swap_bytes(std::span<std::byte> v, std::size_t width);

}  // namespace resoct::detail
