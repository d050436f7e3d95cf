// The zarr v3 codec pipeline, decoded in reverse (bytes->bytes, then array->bytes, then
// array->array), the sharding_indexed index, and CRC-32C. Sizes are known before anything is
// allocated wherever the pipeline allows it; where it does not (a compressor over a nested
// shard) decoders grow with the data actually decoded up to a fixed bound.

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <string>

#include <zstd.h>

#include "io/formats/inflate.hpp"
#include "io/formats/samples.hpp"
#include "io/formats/zarr_codec_steps.hpp"
#include "resoct/io/storage/codec.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/zarr_v3.hpp"

namespace resoct {

namespace {

constexpr std::uint64_t kNoEntry = ~std::uint64_t(0);
/// Bound of a bytes representation whose size the pipeline does not fix (a nested shard under a
/// compressor): the decoded chunk bound plus room for the shard's index.
constexpr std::uint64_t kMaxUnsizedBytes = kMaxZarrChunkBytes + (kMaxZarrShardChunks * 16 + 4);

std::array<std::uint32_t, 256> make_crc32c_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    t[i] = c;
  }
  return t;
}

std::uint32_t load_le32(const std::byte* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

std::uint64_t load_u64(const std::byte* p, Endian e) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) {
    const int shift = e == Endian::little ? 8 * i : 8 * (7 - i);
    v |= std::uint64_t(p[i]) << shift;
  }
  return v;
}

std::string hex32(std::uint32_t v) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s = "0x";
  for (int i = 7; i >= 0; --i) s.push_back(kHex[(v >> (4 * i)) & 15]);
  return s;
}

/// Strips and checks a trailing crc32c; `base` is where `in` starts in its object.
std::span<const std::byte> check_crc32c(std::span<const std::byte> in, std::string_view location,
                                        std::uint64_t base) {
  if (in.size() < 4) {
    throw file_error(
        ErrorCode::truncated, location, base,
        "crc32c codec: " + std::to_string(in.size()) + " bytes, fewer than the checksum");
  }
  const std::span<const std::byte> data = in.first(in.size() - 4);
  const std::uint32_t stored = load_le32(in.data() + data.size());
  const std::uint32_t computed = crc32c(data);
  if (stored != computed) {
    throw file_error(ErrorCode::checksum_mismatch, location, base + data.size(),
                     "crc32c mismatch: stored " + hex32(stored) + ", computed " + hex32(computed) +
                         " over " + std::to_string(data.size()) + " bytes");
  }
  return data;
}

/// zstd frames with or without a content size: streamed into a buffer that grows with the
/// output, never past `max_bytes`.
std::vector<std::byte> zstd_bounded(std::span<const std::byte> in, std::uint64_t max_bytes,
                                    std::string_view location) {
  struct Free {
    void operator()(ZSTD_DCtx* d) const noexcept { ZSTD_freeDCtx(d); }
  };
  std::unique_ptr<ZSTD_DCtx, Free> ctx(ZSTD_createDCtx());
  if (!ctx) throw Error(ErrorCode::out_of_memory, "zstd: cannot create a decompression context");
  std::vector<std::byte> out;
  ZSTD_inBuffer src{in.data(), in.size(), 0};
  std::size_t ret = 1;
  while (true) {
    if (out.size() == max_bytes) {
      throw Error(ErrorCode::out_of_range, std::string(location) + ": zstd data exceed " +
                                               std::to_string(max_bytes) + " decoded bytes");
    }
    const std::size_t used = out.size();
    out.resize(std::size_t(
        std::min<std::uint64_t>(max_bytes, std::max<std::uint64_t>(used * 2, 1 << 16))));
    ZSTD_outBuffer dst{out.data(), out.size(), used};
    ret = ZSTD_decompressStream(ctx.get(), &dst, &src);
    out.resize(dst.pos);
    if (ZSTD_isError(ret)) {
      throw file_error(ErrorCode::decompress_failed, location, src.pos,
                       std::string("zstd rejected the data: ") + ZSTD_getErrorName(ret));
    }
    if (ret == 0 && src.pos == src.size) return out;  // every frame complete
    if (src.pos == src.size && dst.pos < dst.size) {
      throw file_error(ErrorCode::truncated, location, src.pos, "zstd frame ends early");
    }
  }
}

std::uint64_t product(std::span<const std::uint64_t> shape) {
  std::uint64_t n = 1;
  for (std::uint64_t d : shape) n *= d;
  return n;
}

/// Copies a C-order block of shape `block` into the C-order array `dst` of shape `shape` at
/// `origin` (the block lies inside the array).
void copy_block(std::span<const std::byte> src, std::span<const std::uint64_t> block,
                std::span<std::byte> dst, std::span<const std::uint64_t> shape,
                std::span<const std::uint64_t> origin, std::size_t vs) {
  const std::size_t rank = shape.size();
  const std::size_t row = std::size_t(block[rank - 1]) * vs;
  const std::uint64_t rows = product(block) / block[rank - 1];
  std::vector<std::uint64_t> at(rank, 0);  // position inside the block, last dimension 0
  for (std::uint64_t r = 0; r < rows; ++r) {
    std::uint64_t d = 0;
    for (std::size_t i = 0; i < rank; ++i) d = d * shape[i] + origin[i] + at[i];
    std::memcpy(dst.data() + d * vs, src.data() + r * row, row);
    for (std::size_t i = rank - 1; i-- > 0;) {
      if (++at[i] < block[i]) break;
      at[i] = 0;
    }
  }
}

/// Undoes a transpose: `in` has shape t[k] = shape[order[k]]; out[i...] = in[i[order[0]], ...].
std::vector<std::byte> untranspose(std::span<const std::byte> in,
                                   std::span<const std::uint64_t> shape,
                                   std::span<const std::size_t> order, std::size_t vs) {
  const std::size_t rank = shape.size();
  std::vector<std::uint64_t> in_stride(rank, 1);
  for (std::size_t k = rank - 1; k > 0; --k) in_stride[k - 1] = in_stride[k] * shape[order[k]];
  std::vector<std::uint64_t> stride(rank);  // step in `in` per step of output dimension d
  for (std::size_t k = 0; k < rank; ++k) stride[order[k]] = in_stride[k];
  std::vector<std::byte> out(in.size());
  std::vector<std::uint64_t> at(rank, 0);
  const std::uint64_t n = product(shape);
  for (std::uint64_t o = 0; o < n; ++o) {
    std::uint64_t s = 0;
    for (std::size_t d = 0; d < rank; ++d) s += at[d] * stride[d];
    std::memcpy(out.data() + o * vs, in.data() + s * vs, vs);
    for (std::size_t d = rank; d-- > 0;) {
      if (++at[d] < shape[d]) break;
      at[d] = 0;
    }
  }
  return out;
}

std::vector<std::byte> decode_shard_bytes(const ZarrShardingCodec& sharding,
                                          std::span<const std::uint64_t> shape, DataType type,
                                          double fill_value, std::span<const std::byte> shard,
                                          std::string_view location) {
  const std::size_t rank = shape.size();
  std::vector<std::uint64_t> per(rank);
  for (std::size_t d = 0; d < rank; ++d) per[d] = shape[d] / sharding.chunk_shape[d];
  const std::uint64_t n = product(per);
  const std::uint64_t index_bytes = zarr_shard_index_bytes(sharding, n, location);
  if (shard.size() < index_bytes) {
    throw file_error(ErrorCode::truncated, location, 0,
                     "shard of " + std::to_string(shard.size()) + " bytes is shorter than its " +
                         std::to_string(index_bytes) + "-byte index");
  }
  const std::uint64_t index_offset = sharding.index_at_end ? shard.size() - index_bytes : 0;
  const std::size_t vs = voxel_size(data_mapping(type).stored);
  const std::uint64_t inner_bytes = product(sharding.chunk_shape) * vs;
  const auto entries =
      parse_zarr_shard_index(shard.subspan(std::size_t(index_offset), std::size_t(index_bytes)),
                             sharding, n, index_offset, shard.size(), kMaxUnsizedBytes, location);
  std::vector<std::byte> out = zarr_fill_voxels(type, fill_value, product(shape));
  std::vector<std::uint64_t> at(rank, 0), origin(rank);
  for (std::uint64_t i = 0; i < n; ++i) {
    const ZarrShardEntry& e = entries[i];
    if (!e.empty()) {
      for (std::size_t d = 0; d < rank; ++d) origin[d] = at[d] * sharding.chunk_shape[d];
      const std::string where = std::string(location) + " (inner chunk " + std::to_string(i) +
                                " at offset " + std::to_string(e.offset) + ")";
      const auto chunk =
          decode_zarr_v3_chunk(sharding.codecs, sharding.chunk_shape, type, fill_value,
                               shard.subspan(std::size_t(e.offset), std::size_t(e.nbytes)), where);
      if (chunk.size() != inner_bytes) {
        throw Error(ErrorCode::size_mismatch,
                    where + ": decoded to " + std::to_string(chunk.size()) + " bytes");
      }
      copy_block(chunk, sharding.chunk_shape, out, shape, origin, vs);
    }
    for (std::size_t d = rank; d-- > 0;) {
      if (++at[d] < per[d]) break;
      at[d] = 0;
    }
  }
  return out;
}

}  // namespace

std::uint32_t crc32c(std::span<const std::byte> data) noexcept {
  static const std::array<std::uint32_t, 256> table = make_crc32c_table();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::byte b : data) c = table[(c ^ std::uint32_t(b)) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::vector<std::byte> zarr_fill_voxels(DataType file_type, double file_value, std::uint64_t n) {
  const VoxelType type = data_mapping(file_type).stored;
  const double value = file_value + data_mapping(file_type).offset;
  const std::size_t vs = voxel_size(type);
  std::vector<std::byte> out(std::size_t(n) * vs);
  std::array<std::byte, 4> one{};
  switch (type) {
    case VoxelType::u8: one[0] = std::byte(std::uint8_t(value)); break;
    case VoxelType::u16: {
      const auto v = std::uint16_t(value);
      std::memcpy(one.data(), &v, 2);
      break;
    }
    case VoxelType::f32: {
      const auto v = float(value);
      std::memcpy(one.data(), &v, 4);
      break;
    }
  }
  if (vs == 1) {
    std::memset(out.data(), int(one[0]), out.size());
  } else {
    for (std::size_t i = 0; i < out.size(); i += vs) std::memcpy(out.data() + i, one.data(), vs);
  }
  return out;
}

std::uint64_t zarr_shard_index_bytes(const ZarrShardingCodec& sharding,
                                     std::uint64_t chunks_per_shard, std::string_view location) {
  const ZarrCodecs& c = sharding.index_codecs;
  const bool ok = !c.empty() && c[0].kind == ZarrCodecKind::bytes &&
                  (c.size() == 1 || (c.size() == 2 && c[1].kind == ZarrCodecKind::crc32c));
  if (!ok) {
    throw Error(ErrorCode::unsupported,
                std::string(location) +
                    ": key 'index_codecs': only [bytes] or [bytes, crc32c] are supported");
  }
  return chunks_per_shard * 16 + (c.size() == 2 ? 4 : 0);
}

std::vector<ZarrShardEntry> parse_zarr_shard_index(
    std::span<const std::byte> encoded, const ZarrShardingCodec& sharding,
    std::uint64_t chunks_per_shard, std::uint64_t index_offset, std::uint64_t shard_bytes,
    std::uint64_t max_chunk_bytes, std::string_view location) {
  if (chunks_per_shard > kMaxZarrShardChunks) {
    throw invalid_parameter("chunks_per_shard", std::to_string(chunks_per_shard) + " > " +
                                                    std::to_string(kMaxZarrShardChunks));
  }
  const std::uint64_t want = zarr_shard_index_bytes(sharding, chunks_per_shard, location);
  if (encoded.size() != want) {
    throw file_error(ErrorCode::truncated, location, index_offset,
                     "shard index of " + std::to_string(encoded.size()) + " bytes, expected " +
                         std::to_string(want));
  }
  std::span<const std::byte> raw = encoded;
  if (sharding.index_codecs.size() == 2) raw = check_crc32c(encoded, location, index_offset);
  const Endian endian = sharding.index_codecs[0].endian;
  const std::uint64_t index_end = index_offset + want;
  std::vector<ZarrShardEntry> entries(static_cast<std::size_t>(chunks_per_shard));
  std::vector<std::pair<std::uint64_t, std::size_t>> used;  // (offset, entry) of stored chunks
  for (std::size_t i = 0; i < entries.size(); ++i) {
    ZarrShardEntry& e = entries[i];
    e.offset = load_u64(raw.data() + 16 * i, endian);
    e.nbytes = load_u64(raw.data() + 16 * i + 8, endian);
    const std::uint64_t at = index_offset + 16 * i;
    if (e.empty()) continue;
    if (e.offset == kNoEntry || e.nbytes == kNoEntry) {
      throw file_error(ErrorCode::corrupt, location, at,
                       "shard index entry " + std::to_string(i) +
                           " has only one of offset and nbytes set to 2^64-1");
    }
    if (e.nbytes > max_chunk_bytes) {
      throw file_error(ErrorCode::corrupt, location, at,
                       "inner chunk " + std::to_string(i) + " of " + std::to_string(e.nbytes) +
                           " bytes exceeds the limit of " + std::to_string(max_chunk_bytes));
    }
    const std::uint64_t end = e.offset + e.nbytes;  // no overflow: nbytes is bounded
    if (end < e.offset || (shard_bytes != kNoEntry && end > shard_bytes)) {
      throw file_error(ErrorCode::out_of_range, location, at,
                       "inner chunk " + std::to_string(i) + " at " + std::to_string(e.offset) +
                           " + " + std::to_string(e.nbytes) + " bytes runs past the end of the " +
                           (shard_bytes != kNoEntry ? std::to_string(shard_bytes) + "-byte " : "") +
                           "shard");
    }
    if (e.nbytes != 0 && e.offset < index_end && end > index_offset) {
      throw file_error(ErrorCode::out_of_range, location, at,
                       "inner chunk " + std::to_string(i) + " overlaps the shard index");
    }
    if (e.nbytes != 0) used.emplace_back(e.offset, i);
  }
  std::sort(used.begin(), used.end());
  for (std::size_t k = 1; k < used.size(); ++k) {
    const ZarrShardEntry& prev = entries[used[k - 1].second];
    if (prev.offset + prev.nbytes > used[k].first) {
      throw file_error(ErrorCode::corrupt, location, index_offset + 16 * used[k].second,
                       "inner chunk " + std::to_string(used[k].second) + " overlaps inner chunk " +
                           std::to_string(used[k - 1].second));
    }
  }
  return entries;
}

std::vector<std::byte> decode_zarr_v3_chunk(const ZarrCodecs& codecs,
                                            std::span<const std::uint64_t> shape, DataType type,
                                            double fill_value, std::span<const std::byte> encoded,
                                            std::string_view location) {
  // Stored values are data_size(type) bytes each; the decoded array holds voxels of the
  // mapping's type (vs bytes), which transposes and shards move around.
  const std::size_t vs = voxel_size(data_mapping(type).stored);
  const std::size_t value_bytes = data_size(type);
  // Split the pipeline: transposes, the array->bytes codec, bytes->bytes codecs.
  std::size_t ab = 0;
  while (ab < codecs.size() && codecs[ab].kind == ZarrCodecKind::transpose) ++ab;
  if (ab == codecs.size()) {
    throw invalid_parameter("codecs", "no array-to-bytes codec");
  }
  std::vector<std::vector<std::uint64_t>> shapes{
      std::vector<std::uint64_t>(shape.begin(), shape.end())};
  for (std::size_t i = 0; i < ab; ++i) {
    std::vector<std::uint64_t> t(shape.size());
    for (std::size_t d = 0; d < t.size(); ++d) t[d] = shapes.back()[codecs[i].order.at(d)];
    shapes.push_back(t);
  }
  const std::uint64_t array_bytes = product(shape) * value_bytes;  // what `bytes` encodes
  if (array_bytes > kMaxZarrChunkBytes) {
    throw invalid_parameter("shape",
                            "chunk of " + std::to_string(array_bytes) + " bytes is too large");
  }
  // Known bytes size after the array->bytes codec and each bytes->bytes codec (0: unknown).
  std::vector<std::uint64_t> sizes{codecs[ab].kind == ZarrCodecKind::bytes ? array_bytes : 0};
  for (std::size_t i = ab + 1; i < codecs.size(); ++i) {
    const std::uint64_t prev = sizes.back();
    sizes.push_back(codecs[i].kind == ZarrCodecKind::crc32c && prev != 0 ? prev + 4 : 0);
  }

  std::span<const std::byte> bytes = encoded;
  std::vector<std::byte> buffer;  // owns `bytes` once a codec has produced them
  for (std::size_t i = codecs.size(); i-- > ab + 1;) {
    const std::uint64_t want = sizes[i - 1 - ab];  // decoded size of codec i, 0 if unknown
    std::vector<std::byte> next;
    switch (codecs[i].kind) {
      case ZarrCodecKind::crc32c: bytes = check_crc32c(bytes, location, 0); continue;
      case ZarrCodecKind::gzip:
        if (want != 0) {
          next.resize(std::size_t(want));
          detail::inflate_exact(bytes, next, detail::Deflate::gzip, location);
        } else {
          next = detail::inflate_all(bytes, kMaxUnsizedBytes, location);
        }
        break;
      case ZarrCodecKind::zstd:
        if (want != 0) {
          next.resize(std::size_t(want));
          decompress_exact(Codec::zstd, bytes, next, location, 0);
        } else {
          next = zstd_bounded(bytes, kMaxUnsizedBytes, location);
        }
        break;
      case ZarrCodecKind::blosc: {
        const std::uint64_t n = detail::blosc_frame_bytes(bytes, location);
        if (n > kMaxUnsizedBytes || (want != 0 && n != want)) {
          throw Error(ErrorCode::size_mismatch,
                      std::string(location) + ": blosc frame holds " + std::to_string(n) +
                          " bytes, expected " +
                          (want != 0 ? std::to_string(want)
                                     : "at most " + std::to_string(kMaxUnsizedBytes)));
        }
        next.resize(std::size_t(n));
        detail::decode_blosc(bytes, next, location);
        break;
      }
      default: throw invalid_parameter("codecs", "array codec after the bytes codec");
    }
    buffer = std::move(next);
    bytes = buffer;
  }

  const std::span<const std::uint64_t> stored_shape = shapes.back();
  std::vector<std::byte> array;
  if (codecs[ab].kind == ZarrCodecKind::bytes) {
    if (bytes.size() != array_bytes) {
      throw Error(ErrorCode::size_mismatch, std::string(location) + ": chunk decodes to " +
                                                std::to_string(bytes.size()) + " bytes, expected " +
                                                std::to_string(array_bytes));
    }
    if (detail::samples_are_voxels(type, codecs[ab].endian, false)) {
      array.assign(bytes.begin(), bytes.end());
    } else {  // another byte order, a signed type kept with an offset, a wide type as f32
      array.resize(std::size_t(product(shape)) * vs);
      detail::convert_samples(bytes, type, codecs[ab].endian, false, 1.0, 0.0, array);
    }
  } else if (codecs[ab].kind == ZarrCodecKind::sharding_indexed) {
    array =
        decode_shard_bytes(*codecs[ab].sharding, stored_shape, type, fill_value, bytes, location);
  } else {
    throw invalid_parameter("codecs", "bytes-to-bytes codec in place of the array-to-bytes codec");
  }
  for (std::size_t i = ab; i-- > 0;) {
    array = untranspose(array, shapes[i], codecs[i].order, vs);
  }
  return array;
}

}  // namespace resoct
