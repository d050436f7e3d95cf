#include <cstring>
#include <string>

#include <blosc.h>

#include "io/formats/inflate.hpp"
#include "io/formats/samples.hpp"
#include "io/formats/zarr_codec_steps.hpp"
#include "resoct/io/storage/codec.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/zarr_array.hpp"

namespace resoct {

namespace detail {

std::uint64_t blosc_frame_bytes(std::span<const std::byte> in, std::string_view location) {
  // blosc_cbuffer_validate checks the header against the buffer length before anything is
  // read past it.
  std::size_t nbytes = 0;
  if (in.size() < BLOSC_MIN_HEADER_LENGTH ||
      blosc_cbuffer_validate(in.data(), in.size(), &nbytes) != 0) {
    throw Error(ErrorCode::corrupt, std::string(location) +
                                        ": offset 0: not a valid blosc frame (" +
                                        std::to_string(in.size()) + " bytes)");
  }
  return nbytes;
}

void decode_blosc(std::span<const std::byte> in, std::span<std::byte> out,
                  std::string_view location) {
  // blosc_decompress_ctx never writes more than destsize.
  const std::uint64_t nbytes = blosc_frame_bytes(in, location);
  if (nbytes != out.size()) {
    throw Error(ErrorCode::size_mismatch, std::string(location) + ": blosc frame holds " +
                                              std::to_string(nbytes) + " bytes, the chunk " +
                                              std::to_string(out.size()));
  }
  if (out.empty()) return;
  const int n = blosc_decompress_ctx(in.data(), out.data(), out.size(), 1);
  if (n < 0 || std::size_t(n) != out.size()) {
    throw Error(ErrorCode::decompress_failed,
                std::string(location) + ": blosc decompression failed (code " + std::to_string(n) +
                    "; inner codec missing from libblosc or damaged data)");
  }
}

void swap_bytes(std::span<std::byte> v, std::size_t width) {
  for (std::size_t i = 0; i + width <= v.size(); i += width) {
    for (std::size_t a = 0, b = width - 1; a < b; ++a, --b) std::swap(v[i + a], v[i + b]);
  }
}

}  // namespace detail

namespace {

void decode_lz4(std::span<const std::byte> in, std::span<std::byte> out,
                std::string_view location) {
  // numcodecs.LZ4 prefixes the block with its decoded size as a little-endian uint32.
  if (in.size() < 4) {
    throw Error(ErrorCode::corrupt,
                std::string(location) + ": offset 0: lz4 chunk shorter than its 4-byte header");
  }
  const std::uint32_t size = std::uint32_t(in[0]) | std::uint32_t(in[1]) << 8 |
                             std::uint32_t(in[2]) << 16 | std::uint32_t(in[3]) << 24;
  if (size != out.size()) {
    throw Error(ErrorCode::size_mismatch, std::string(location) + ": offset 0: lz4 header says " +
                                              std::to_string(size) + " bytes, the chunk holds " +
                                              std::to_string(out.size()));
  }
  decompress_exact(Codec::lz4, in.subspan(4), out, location, 4);
}

}  // namespace

std::vector<std::byte> decode_zarr_chunk(const ZarrArrayMeta& meta,
                                         std::span<const std::byte> encoded,
                                         std::string_view location) {
  const std::uint64_t bytes = meta.stored_chunk_bytes();
  if (bytes > kMaxZarrChunkBytes) {
    throw invalid_parameter("meta", "chunk of " + std::to_string(bytes) + " bytes is too large");
  }
  std::vector<std::byte> out(static_cast<std::size_t>(bytes));
  switch (meta.compressor) {
    case ZarrCompressor::none:
      if (encoded.size() != out.size()) {
        throw Error(ErrorCode::size_mismatch, std::string(location) + ": uncompressed chunk of " +
                                                  std::to_string(encoded.size()) +
                                                  " bytes, expected " + std::to_string(out.size()));
      }
      if (!out.empty()) std::memcpy(out.data(), encoded.data(), out.size());
      break;
    case ZarrCompressor::blosc: detail::decode_blosc(encoded, out, location); break;
    case ZarrCompressor::lz4: decode_lz4(encoded, out, location); break;
    case ZarrCompressor::zstd: decompress_exact(Codec::zstd, encoded, out, location, 0); break;
    case ZarrCompressor::zlib:
      detail::inflate_exact(encoded, out, detail::Deflate::zlib, location);
      break;
    case ZarrCompressor::gzip:
      detail::inflate_exact(encoded, out, detail::Deflate::gzip, location);
      break;
  }
  if (detail::samples_are_voxels(meta.data_type, meta.endian, false)) return out;
  // Another byte order, a signed type kept with an offset, or a wide type kept as f32.
  std::vector<std::byte> voxels(static_cast<std::size_t>(meta.chunk_bytes()));
  detail::convert_samples(out, meta.data_type, meta.endian, false, 1.0, 0.0, voxels);
  return voxels;
}

}  // namespace resoct
