#include "io/formats/inflate.hpp"

#include <algorithm>
#include <climits>
#include <string>

#include <zlib.h>

#include "resoct/base/error.hpp"

namespace resoct::detail {

namespace {

int window_bits(Deflate f) {
  switch (f) {
    case Deflate::zlib: return 15;
    case Deflate::gzip: return 15 + 16;
    case Deflate::any: return 15 + 32;
  }
  return 15;
}

/// Owns one z_stream; inflateEnd on every exit path.
class Inflater {
 public:
  Inflater(Deflate f, std::string_view location) : location_(location) {
    if (inflateInit2(&z_, window_bits(f)) != Z_OK) {
      throw Error(ErrorCode::out_of_memory, std::string(location) + ": zlib initialisation failed");
    }
  }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;
  ~Inflater() { inflateEnd(&z_); }

  /// Inflates from `in` into `out` until one of them is exhausted or the stream ends; returns
  /// bytes written. Follows concatenated gzip members.
  std::size_t run(std::span<const std::byte>& in, std::span<std::byte> out, bool& ended) {
    std::size_t written = 0;
    ended = false;
    while (true) {
      const uInt in_chunk = uInt(std::min<std::size_t>(in.size(), UINT_MAX / 2));
      const uInt out_chunk = uInt(std::min<std::size_t>(out.size() - written, UINT_MAX / 2));
      z_.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data()));
      z_.avail_in = in_chunk;
      z_.next_out = reinterpret_cast<Bytef*>(out.data() + written);
      z_.avail_out = out_chunk;
      const int rc = inflate(&z_, Z_NO_FLUSH);
      const std::size_t consumed = in_chunk - z_.avail_in;
      written += out_chunk - z_.avail_out;
      in = in.subspan(consumed);
      if (rc == Z_STREAM_END) {
        // Another gzip member may follow (gzip allows concatenation).
        if (in.size() >= 2 && is_gzip(in)) {
          inflateReset(&z_);
          continue;
        }
        ended = true;
        return written;
      }
      if (rc == Z_BUF_ERROR && (in.empty() || written == out.size())) return written;
      if (rc != Z_OK) {
        throw Error(ErrorCode::decompress_failed,
                    std::string(location_) + ": offset " + std::to_string(z_.total_in) +
                        ": zlib: " + (z_.msg != nullptr ? z_.msg : "invalid stream"));
      }
      if (in.empty() || written == out.size()) return written;
    }
  }
  std::uint64_t total_in() const noexcept { return z_.total_in; }

 private:
  z_stream z_{};
  std::string_view location_;
};

}  // namespace

bool is_gzip(std::span<const std::byte> bytes) noexcept {
  return bytes.size() >= 2 && bytes[0] == std::byte{0x1f} && bytes[1] == std::byte{0x8b};
}

void inflate_exact(std::span<const std::byte> in, std::span<std::byte> out, Deflate framing,
                   std::string_view location) {
  Inflater z(framing, location);
  bool ended = false;
  const std::size_t n = z.run(in, out, ended);
  if (n != out.size()) {
    throw Error(ErrorCode::size_mismatch, std::string(location) + ": deflate stream holds " +
                                              std::to_string(n) + " bytes, expected " +
                                              std::to_string(out.size()));
  }
  if (!ended) {
    // Full output but no stream end: probe for surplus data.
    std::byte probe[1];
    const std::size_t extra = z.run(in, probe, ended);
    if (extra != 0) {
      throw Error(ErrorCode::size_mismatch, std::string(location) +
                                                ": deflate stream holds more than the expected " +
                                                std::to_string(out.size()) + " bytes");
    }
  }
}

std::vector<std::byte> inflate_all(std::span<const std::byte> in, std::uint64_t max_bytes,
                                   std::string_view location, bool stop_at_max) {
  Inflater z(Deflate::any, location);
  std::vector<std::byte> out;
  std::size_t used = 0;
  bool ended = false;
  while (!ended) {
    if (used == out.size()) {
      if (stop_at_max && out.size() >= max_bytes) break;
      if (out.size() >= max_bytes) {
        throw Error(ErrorCode::out_of_range, std::string(location) +
                                                 ": decompressed data exceeds the limit of " +
                                                 std::to_string(max_bytes) + " bytes");
      }
      out.resize(std::size_t(std::min<std::uint64_t>(
          max_bytes, std::max<std::uint64_t>(1 << 20, std::uint64_t(out.size()) * 2))));
    }
    const std::size_t before = in.size();
    const std::size_t n = z.run(in, std::span(out).subspan(used), ended);
    used += n;
    if (!ended && in.empty() && n == 0 && before == 0) {
      throw Error(ErrorCode::truncated, std::string(location) + ": offset " +
                                            std::to_string(z.total_in()) +
                                            ": compressed stream ends early");
    }
    if (!ended && in.empty() && used < out.size()) {
      throw Error(ErrorCode::truncated, std::string(location) + ": offset " +
                                            std::to_string(z.total_in()) +
                                            ": compressed stream ends early");
    }
  }
  if (!ended) {
    // Stopped at max_bytes: decode on into scratch so that a stream ending soon after is checked
    // to its end (the gzip CRC catches damage the deflate codes did not). Surplus beyond 1 MiB
    // is not examined.
    std::vector<std::byte> scratch(1 << 16);
    std::uint64_t surplus = 0;
    while (!ended && surplus < (1u << 20)) {
      const std::size_t n = z.run(in, scratch, ended);
      if (n == 0 && !ended) break;
      surplus += n;
    }
  }
  out.resize(used);
  return out;
}

}  // namespace resoct::detail
