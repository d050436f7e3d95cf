#pragma once
/// \file
/// Zarr v3 arrays (the format under OME-Zarr 0.5): the array `zarr.json`, the codec pipeline
/// and the index of a `sharding_indexed` shard. Parsers and decoders are free functions over
/// bytes, so fuzz targets call exactly what the zarr source calls.
///
/// Supported: data types uint8, int8, uint16, int16, uint32, int32, float32, float64, kept through
/// data_mapping() (voxel_type.hpp); chunk grid "regular"; chunk key encodings "default" and "v2"
/// with separator '/' or '.'; codecs transpose, bytes (little/big), blosc, gzip, zstd, crc32c
/// and sharding_indexed (index at start or end, nested sharding). A shard whose pipeline is
/// exactly [sharding_indexed] is read by ranges (index, then one inner chunk); a sharding codec
/// anywhere else (after a transpose, followed by bytes-to-bytes codecs, or nested inside another
/// shard's inner chunks) is decoded from the bytes of its whole chunk.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "resoct/io/formats/zarr_array.hpp"

namespace resoct {

/// The codecs resoct decodes (zarr v3 codec names).
enum class ZarrCodecKind : std::uint8_t {
  transpose,         ///< array -> array
  bytes,             ///< array -> bytes
  sharding_indexed,  ///< array -> bytes
  blosc,             ///< bytes -> bytes
  gzip,              ///< bytes -> bytes
  zstd,              ///< bytes -> bytes
  crc32c,            ///< bytes -> bytes
};

struct ZarrShardingCodec;

/// One entry of a codec pipeline.
struct ZarrCodec {
  ZarrCodecKind kind = ZarrCodecKind::bytes;
  std::vector<std::size_t> order;  ///< transpose: a permutation of the chunk's dimensions
  Endian endian = Endian::little;  ///< bytes: byte order of multi-byte voxels
  std::shared_ptr<const ZarrShardingCodec> sharding;  ///< sharding_indexed: its configuration
};

/// A pipeline in encoding order: array->array codecs, one array->bytes codec, bytes->bytes
/// codecs. Decoding runs it in reverse.
using ZarrCodecs = std::vector<ZarrCodec>;

/// `sharding_indexed` configuration.
struct ZarrShardingCodec {
  std::vector<std::uint64_t> chunk_shape;  ///< inner chunk shape; divides the shard shape
  ZarrCodecs codecs;                       ///< pipeline of each inner chunk
  ZarrCodecs index_codecs;                 ///< pipeline of the index: bytes, then crc32c or not
  bool index_at_end = true;                ///< index_location "end" (default) or "start"
};

/// What a v3 array adds to ZarrArrayMeta (ZarrArrayMeta::v3).
struct ZarrV3Layout {
  ZarrCodecs codecs;  ///< the array's pipeline (encoding order)
  /// The chunk grid's chunk shape when the array is read shard by shard (codecs is exactly one
  /// sharding_indexed codec); ZarrArrayMeta::chunks is then the inner chunk shape, the unit
  /// that is read and cached. Empty otherwise (ZarrArrayMeta::chunks is the grid's shape).
  std::vector<std::uint64_t> shard_shape;
  std::vector<std::string> dimension_names;  ///< "" for null entries; empty when absent
};

/// Largest shard index accepted (inner chunks per shard): 2^20 entries, 16 MiB of index. A
/// hostile chunk_shape must not make the reader allocate an index without bound.
inline constexpr std::uint64_t kMaxZarrShardChunks = std::uint64_t(1) << 20;

/// Maps a v3 `data_type` name to a DataType: "uint8", "int8", "uint16", "int16", "uint32",
/// "int32", "float32", "float64". Anything else (bool, int64, complex, ...) throws
/// Error(unsupported) naming `location`, `key` and the type.
DataType parse_zarr_v3_data_type(std::string_view name, std::string_view location,
                                 std::string_view key);

/// Parses an array `zarr.json` (zarr_format 3, node_type "array"). The result has
/// zarr_format 3, chunks = the unit read (inner chunk when sharded), chunk_key_prefix per the
/// chunk key encoding, and `v3` set. `location` names the file in messages. Throws
/// Error(corrupt) naming location and the key for malformed JSON, missing or mistyped keys,
/// rank mismatches, zero sizes, a chunk above kMaxZarrChunkBytes decoded or a shard above
/// kMaxZarrShardChunks inner chunks, an inner chunk shape that does not divide the shard shape, a
/// transpose order that is no permutation; Error(unsupported_version) for zarr_format != 3;
/// Error(unsupported) naming the key for an unknown codec, chunk grid, chunk key encoding,
/// data type or codec (every unknown codec is rejected: none can be skipped safely), and for
/// dimension_names of the wrong rank. Thread-safety: pure.
ZarrArrayMeta parse_zarr_v3_array_meta(std::string_view json, std::string_view location);

/// One inner chunk's place in its shard: `nbytes` bytes at `offset`. Both 2^64-1: the chunk is
/// absent (fill value).
struct ZarrShardEntry {
  std::uint64_t offset = 0;
  std::uint64_t nbytes = 0;
  bool empty() const noexcept { return offset == ~std::uint64_t(0) && nbytes == ~std::uint64_t(0); }
};

/// Bytes of a shard's encoded index for `chunks_per_shard` inner chunks (16 per chunk, plus 4
/// with crc32c). Throws Error(unsupported) naming `location` for index codecs other than bytes
/// followed by an optional crc32c.
std::uint64_t zarr_shard_index_bytes(const ZarrShardingCodec& sharding,
                                     std::uint64_t chunks_per_shard, std::string_view location);

/// Decodes and validates a shard's index: `encoded` is exactly zarr_shard_index_bytes() bytes,
/// `index_offset` where they sit in the shard of `shard_bytes` bytes (pass ~0 when the shard's
/// size is unknown: then only the index's own consistency is checked). Throws
/// Error(checksum_mismatch) for a bad crc32c, Error(truncated) for an index of another size,
/// Error(out_of_range) for an entry past the end of the shard or over the index, Error(corrupt)
/// for an entry with one of offset/nbytes 2^64-1, overlapping entries or an entry larger than
/// `max_chunk_bytes`; every message names `location` and the offset of the entry in the shard.
/// Thread-safety: pure.
std::vector<ZarrShardEntry> parse_zarr_shard_index(
    std::span<const std::byte> encoded, const ZarrShardingCodec& sharding,
    std::uint64_t chunks_per_shard, std::uint64_t index_offset, std::uint64_t shard_bytes,
    std::uint64_t max_chunk_bytes, std::string_view location);

/// Decodes one chunk of shape `shape` of `type` values encoded with `codecs` into native-endian
/// C-order voxels of data_mapping(type).stored (values mapped); `fill_value` (file units) fills
/// empty inner chunks of nested shards. Throws
/// Error(checksum_mismatch) naming location and offset for a bad crc32c, Error(size_mismatch)
/// when the data decode to another size, Error(decompress_failed) / Error(corrupt) for data the
/// codec rejects. Thread-safety: pure.
std::vector<std::byte> decode_zarr_v3_chunk(const ZarrCodecs& codecs,
                                            std::span<const std::uint64_t> shape, DataType type,
                                            double fill_value, std::span<const std::byte> encoded,
                                            std::string_view location);

/// `n` voxels holding the file value `value` of `type` as data_mapping(type) keeps it,
/// native-endian.
std::vector<std::byte> zarr_fill_voxels(DataType type, double value, std::uint64_t n);

/// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), as the zarr crc32c codec stores it.
std::uint32_t crc32c(std::span<const std::byte> data) noexcept;

}  // namespace resoct
