#pragma once
/// \file
/// Zarr arrays: the `.zarray` metadata (v2) and the decoding of one stored v2 chunk. The same
/// ZarrArrayMeta describes a v3 array (zarr_v3.hpp parses its `zarr.json` and decodes its
/// codec pipeline; `v3` then holds the codecs and the shard shape). Parsers are free
/// functions over bytes so that fuzz targets and the HTTP reader call exactly what the zarr
/// source calls. Supported: dtypes u1, i1, u2, i2, u4, i4, f4, f8 of either byte order (kept
/// through data_mapping(), voxel_type.hpp: i1 / i2 exactly with an offset, u4, i4 and f8 as f32,
/// rounded); C order; no filters; compressors
/// blosc (any inner codec libblosc was built with, byte or bit shuffle), lz4 (numcodecs framing:
/// a 4-byte little-endian size, then one LZ4 block), zstd, zlib, gzip, none.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "resoct/io/formats/raw_volume.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

struct ZarrV3Layout;  // zarr_v3.hpp

/// How a chunk is compressed (numcodecs ids).
enum class ZarrCompressor : std::uint8_t { none, blosc, lz4, zstd, zlib, gzip };

/// "none", "blosc", "lz4", "zstd", "zlib", "gzip".
std::string_view to_string(ZarrCompressor c) noexcept;

/// Largest decoded chunk the reader accepts (a hostile `.zarray` must not make it allocate
/// without bound): 1 GiB.
inline constexpr std::uint64_t kMaxZarrChunkBytes = std::uint64_t(1) << 30;

/// The parsed `.zarray` of one array. Dimensions are in the array's own axis order, slowest
/// first (C order).
struct ZarrArrayMeta {
  std::vector<std::uint64_t> shape;   ///< voxels per dimension, each >= 1
  std::vector<std::uint64_t> chunks;  ///< chunk shape, same rank, each >= 1
  DataType data_type = DataType::u8;  ///< type of the stored values (the dtype)
  VoxelType type = VoxelType::u8;     ///< decoded voxel type: data_mapping(data_type).stored
  Endian endian = Endian::little;     ///< byte order of stored multi-byte values
  ZarrCompressor compressor = ZarrCompressor::none;
  double fill_value = 0.0;         ///< value of voxels in missing chunks (null: 0), file units
  char dimension_separator = '.';  ///< '.' or '/' between chunk indices in chunk keys
  int zarr_format = 2;             ///< 2 or 3
  /// Before the chunk indices in a chunk key: "" (v2, and v3 "v2" encoding), "c/" or "c." (v3
  /// "default" encoding).
  std::string chunk_key_prefix;
  /// v3 only (null for v2): codec pipeline, shard shape, dimension names. `compressor` and
  /// `endian` are then unused.
  std::shared_ptr<const ZarrV3Layout> v3;

  /// Chunks per dimension: ceil(shape / chunks).
  std::vector<std::uint64_t> chunk_grid() const;
  /// Voxels in one (full) chunk.
  std::uint64_t chunk_voxels() const;
  /// Decoded bytes of one chunk as resoct voxels: chunk_voxels() * voxel_size(type).
  std::uint64_t chunk_bytes() const { return chunk_voxels() * voxel_size(type); }
  /// Bytes of one chunk as stored values before compression: chunk_voxels() * data_size(data_type).
  std::uint64_t stored_chunk_bytes() const { return chunk_voxels() * data_size(data_type); }
  /// The store key of a chunk relative to the array: "2.0.13", "2/0/13", "c/2/0/13". For a
  /// sharded v3 array `chunk_index` indexes the chunk grid (shards), not inner chunks.
  std::string chunk_key(std::span<const std::uint64_t> chunk_index) const;
};

/// Parses `.zarray` JSON. `location` names the file in messages. Throws Error(corrupt) naming
/// location and the key for malformed JSON, missing or mistyped keys, a rank mismatch between
/// shape and chunks, zero sizes or a chunk above kMaxZarrChunkBytes; Error(unsupported_version)
/// for zarr_format != 2; Error(unsupported) naming the key for F order, filters, an unknown
/// compressor or an unsupported dtype. Thread-safety: a pure function.
ZarrArrayMeta parse_zarr_array_meta(std::string_view json, std::string_view location);

/// Decodes one stored chunk into its chunk_bytes() native-endian voxels, values mapped by
/// data_mapping(data_type) (zarr stores border
/// chunks at full size too). Throws Error(decompress_failed) naming `location` when the codec
/// rejects the bytes, Error(size_mismatch) when they decode to another size than the chunk,
/// Error(corrupt) for a damaged blosc or lz4 header. Thread-safety: a pure function.
std::vector<std::byte> decode_zarr_chunk(const ZarrArrayMeta& meta,
                                         std::span<const std::byte> encoded,
                                         std::string_view location);

}  // namespace resoct
