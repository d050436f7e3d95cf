#pragma once
// zlib inflation shared by the zarr, NIfTI and NRRD readers (internal).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace resoct::detail {

/// Which zlib framing to accept.
enum class Deflate { zlib, gzip, any };

/// Inflates `in` into exactly `out.size()` bytes. Throws Error(decompress_failed) naming
/// `location` when zlib rejects the stream and Error(size_mismatch) when it ends early or holds
/// more. Concatenated gzip members are followed. Thread-safe.
void inflate_exact(std::span<const std::byte> in, std::span<std::byte> out, Deflate framing,
                   std::string_view location);

/// Inflates a gzip (or zlib) stream of unknown decoded size. The buffer grows with the data
/// actually decoded, never beyond `max_bytes`: past it, Error(out_of_range) — or, with
/// `stop_at_max`, the first `max_bytes` bytes are returned (a prefix such as a header, or data
/// followed by bytes the caller does not need). A stream that ends early is Error(truncated)
/// naming `location` and the compressed offset. Thread-safe.
std::vector<std::byte> inflate_all(std::span<const std::byte> in, std::uint64_t max_bytes,
                                   std::string_view location, bool stop_at_max = false);

/// True when the bytes start with the gzip magic 1f 8b.
bool is_gzip(std::span<const std::byte> bytes) noexcept;

}  // namespace resoct::detail
