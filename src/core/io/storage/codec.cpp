#include "resoct/io/storage/codec.hpp"

#include <limits>
#include <memory>
#include <string>

#include <lz4.h>
#include <lz4hc.h>
#include <zstd.h>
#include <zstd_errors.h>

#include "resoct/base/error.hpp"

namespace resoct {

std::string_view to_string(Codec c) noexcept {
  switch (c) {
    case Codec::lz4: return "lz4";
    case Codec::zstd: return "zstd";
  }
  return "unknown";
}

std::optional<Codec> parse_codec(std::string_view s) noexcept {
  if (s == "lz4") return Codec::lz4;
  if (s == "zstd") return Codec::zstd;
  return std::nullopt;
}

void validate_codec_level(Codec c, int level) {
  switch (c) {
    case Codec::lz4:
      // Acceleration above 65537 is clamped by LZ4 anyway; reject it so a typo is noticed.
      if (level < -65537 || level > LZ4HC_CLEVEL_MAX) {
        throw invalid_parameter("level", "lz4 takes -65537..12, got " + std::to_string(level));
      }
      return;
    case Codec::zstd:
      if (level != 0 && (level < ZSTD_minCLevel() || level > ZSTD_maxCLevel())) {
        throw invalid_parameter("level", "zstd takes " + std::to_string(ZSTD_minCLevel()) + ".." +
                                             std::to_string(ZSTD_maxCLevel()) + ", got " +
                                             std::to_string(level));
      }
      return;
  }
  throw invalid_parameter("codec", "unknown codec " + std::to_string(int(c)));
}

std::size_t compress_bound(Codec c, std::size_t n) {
  switch (c) {
    case Codec::lz4:
      if (n > std::size_t(LZ4_MAX_INPUT_SIZE)) {
        throw invalid_parameter("codec", "lz4 compresses at most " +
                                             std::to_string(LZ4_MAX_INPUT_SIZE) +
                                             " bytes per brick, got " + std::to_string(n));
      }
      return std::size_t(LZ4_compressBound(int(n)));
    case Codec::zstd: return ZSTD_compressBound(n);
  }
  throw invalid_parameter("codec", "unknown codec " + std::to_string(int(c)));
}

namespace {
struct CCtxDeleter {
  void operator()(ZSTD_CCtx* c) const noexcept { ZSTD_freeCCtx(c); }
};
struct DCtxDeleter {
  void operator()(ZSTD_DCtx* d) const noexcept { ZSTD_freeDCtx(d); }
};

// One context per thread: creating a zstd context per brick costs more than decoding a small
// brick, and contexts must not be shared between threads.
ZSTD_CCtx* thread_cctx() {
  thread_local std::unique_ptr<ZSTD_CCtx, CCtxDeleter> ctx(ZSTD_createCCtx());
  if (!ctx) throw Error(ErrorCode::out_of_memory, "zstd: cannot create a compression context");
  return ctx.get();
}
ZSTD_DCtx* thread_dctx() {
  thread_local std::unique_ptr<ZSTD_DCtx, DCtxDeleter> ctx(ZSTD_createDCtx());
  if (!ctx) throw Error(ErrorCode::out_of_memory, "zstd: cannot create a decompression context");
  return ctx.get();
}
}  // namespace

std::vector<std::byte> compress(Codec c, int level, std::span<const std::byte> in) {
  validate_codec_level(c, level);
  std::vector<std::byte> out(compress_bound(c, in.size()));
  const auto* src = reinterpret_cast<const char*>(in.data());
  auto* dst = reinterpret_cast<char*>(out.data());
  std::size_t written = 0;
  if (c == Codec::lz4) {
    int n = 0;
    if (level > 0) {
      n = LZ4_compress_HC(src, dst, int(in.size()), int(out.size()), level);
    } else {
      n = LZ4_compress_fast(src, dst, int(in.size()), int(out.size()), level < 0 ? -level : 1);
    }
    if (n <= 0 && !in.empty()) {
      throw Error(ErrorCode::invalid_argument,
                  "lz4: compression of " + std::to_string(in.size()) + " bytes failed");
    }
    written = std::size_t(n);
  } else {
    const std::size_t n = ZSTD_compressCCtx(thread_cctx(), dst, out.size(), src, in.size(),
                                            level == 0 ? ZSTD_CLEVEL_DEFAULT : level);
    if (ZSTD_isError(n)) {
      throw Error(ErrorCode::invalid_argument,
                  std::string("zstd: compression failed: ") + ZSTD_getErrorName(n));
    }
    written = n;
  }
  out.resize(written);
  return out;
}

void decompress_exact(Codec c, std::span<const std::byte> in, std::span<std::byte> out,
                      std::string_view file, std::uint64_t offset) {
  const auto* src = reinterpret_cast<const char*>(in.data());
  auto* dst = reinterpret_cast<char*>(out.data());
  const std::string want = std::to_string(out.size());
  if (c == Codec::lz4) {
    if (in.size() > std::size_t(std::numeric_limits<int>::max()) ||
        out.size() > std::size_t(std::numeric_limits<int>::max())) {
      throw file_error(ErrorCode::decompress_failed, file, offset,
                       "lz4 payload or brick larger than lz4 can decode");
    }
    const int n = LZ4_decompress_safe(src, dst, int(in.size()), int(out.size()));
    if (n < 0) {
      throw file_error(
          ErrorCode::decompress_failed, file, offset,
          "lz4 rejected the payload (corrupt, or it decodes to more than " + want + " bytes)");
    }
    if (std::size_t(n) != out.size()) {
      throw file_error(ErrorCode::size_mismatch, file, offset,
                       "lz4 payload decodes to " + std::to_string(n) + " bytes, expected " + want);
    }
    return;
  }
  if (c != Codec::zstd) {
    throw file_error(ErrorCode::corrupt, file, offset, "unknown codec " + std::to_string(int(c)));
  }
  // The frame header announces the size; checking it first names the real problem instead of a
  // generic "destination too small".
  const unsigned long long announced = ZSTD_getFrameContentSize(src, in.size());
  if (announced == ZSTD_CONTENTSIZE_ERROR) {
    throw file_error(ErrorCode::decompress_failed, file, offset,
                     "zstd rejected the payload (no valid frame header)");
  }
  if (announced != ZSTD_CONTENTSIZE_UNKNOWN && announced != out.size()) {
    throw file_error(
        ErrorCode::size_mismatch, file, offset,
        "zstd payload announces " + std::to_string(announced) + " bytes, expected " + want);
  }
  const std::size_t n = ZSTD_decompressDCtx(thread_dctx(), dst, out.size(), src, in.size());
  if (ZSTD_isError(n)) {
    if (ZSTD_getErrorCode(n) == ZSTD_error_dstSize_tooSmall) {
      throw file_error(ErrorCode::size_mismatch, file, offset,
                       "zstd payload decodes to more than " + want + " bytes");
    }
    throw file_error(ErrorCode::decompress_failed, file, offset,
                     std::string("zstd rejected the payload: ") + ZSTD_getErrorName(n));
  }
  if (n != out.size()) {
    throw file_error(ErrorCode::size_mismatch, file, offset,
                     "zstd payload decodes to " + std::to_string(n) + " bytes, expected " + want);
  }
}

}  // namespace resoct
