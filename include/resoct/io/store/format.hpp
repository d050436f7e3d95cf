#pragma once
/// \file
/// Byte layout of the brick store file (docs/brick-store-format.md): explicit little-endian
/// encoding of the header, the brick index entries and the metadata section. Internal to the
/// store reader and writer; not a public API.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "resoct/io/storage/codec.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/sources/metadata_pyramid.hpp"

namespace resoct::detail {

/// PNG-style magic: a non-ASCII first byte and CR LF / ^Z / LF catch text-mode transfers.
inline constexpr std::array<std::uint8_t, 8> kStoreMagic = {0x89, 'R',  'B',  'S',
                                                            0x0D, 0x0A, 0x1A, 0x0A};
inline constexpr std::uint32_t kStoreVersion = 1;

/// Byte offsets of the version-1 header fields (all little-endian).
namespace hdr {
inline constexpr std::uint64_t magic = 0;
inline constexpr std::uint64_t version = 8;
inline constexpr std::uint64_t header_size = 12;
inline constexpr std::uint64_t flags = 16;
inline constexpr std::uint64_t voxel_type = 20;
inline constexpr std::uint64_t extent = 24;   // 3 x u64
inline constexpr std::uint64_t spacing = 48;  // 3 x f64
inline constexpr std::uint64_t channels = 72;
inline constexpr std::uint64_t brick_size = 76;  // 3 x u32
inline constexpr std::uint64_t halo = 88;
inline constexpr std::uint64_t codec = 92;
inline constexpr std::uint64_t codec_level = 96;  // i32
inline constexpr std::uint64_t metadata_block = 100;
inline constexpr std::uint64_t level_count = 104;
inline constexpr std::uint64_t index_crc = 108;
inline constexpr std::uint64_t bricks_per_channel = 112;
inline constexpr std::uint64_t payload_offset = 120;
inline constexpr std::uint64_t payload_size = 128;
inline constexpr std::uint64_t index_offset = 136;
inline constexpr std::uint64_t index_size = 144;
inline constexpr std::uint64_t metadata_offset = 152;
inline constexpr std::uint64_t metadata_size = 160;
inline constexpr std::uint64_t metadata_raw_size = 168;
inline constexpr std::uint64_t metadata_crc = 176;
/// 0: the values are voxel_type's own; else the DataType code (3..7) of the file the store was
/// converted from, whose data_mapping() gives voxel_type (VolumeDesc::data_type).
inline constexpr std::uint64_t data_type = 180;
inline constexpr std::uint64_t ranges = 184;  // channels x (f64 lo, f64 hi), [origin], the CRC
/// Fixed part before the ranges plus the trailing CRC.
inline constexpr std::uint64_t fixed_size = 188;
}  // namespace hdr

/// Header flag: the volume had no explicit value ranges (the stored ones are the defaults).
inline constexpr std::uint32_t kFlagDefaultRanges = 1u << 0;
/// Header flag: 3 f64 (the volume's origin, VolumeDesc::origin) follow the ranges. Set only for
/// an origin other than 0, so stores of unplaced volumes stay byte-identical to those written
/// before the flag existed; a reader that does not know the flag refuses the file
/// (Error(unsupported)) instead of silently misplacing it.
inline constexpr std::uint32_t kFlagOrigin = 1u << 1;
/// Header flag: the store holds every brick's down-sampling error (BrickSource::brick_error): 24
/// bytes follow the ranges and the origin (the errors section's offset, compressed size and
/// CRC-32, and a reserved zero word), and the section is one zstd frame of one f32 per brick and
/// channel, in index order. Set only by a writer asked for errors, so other stores stay
/// byte-identical to those written before the flag existed.
inline constexpr std::uint32_t kFlagBrickErrors = 1u << 2;
inline constexpr std::uint32_t kKnownFlags = kFlagDefaultRanges | kFlagOrigin | kFlagBrickErrors;

/// Bytes of the errors section's header fields (kFlagBrickErrors) and their offsets within them.
inline constexpr std::uint64_t kErrorFieldsSize = 24;
inline constexpr std::uint64_t kErrorFieldOffset = 0;     // u64 errors section offset
inline constexpr std::uint64_t kErrorFieldSize = 8;       // u64 compressed bytes
inline constexpr std::uint64_t kErrorFieldCrc = 16;       // u32 CRC-32 of the compressed bytes
inline constexpr std::uint64_t kErrorFieldReserved = 20;  // u32, must be 0
/// Bytes per brick and channel in the raw errors section (f32).
inline constexpr std::uint64_t kErrorEntrySize = 4;

/// Index entry flags.
inline constexpr std::uint32_t kEntryStored = 1u << 0;    ///< a payload exists
inline constexpr std::uint32_t kEntryConstant = 1u << 1;  ///< BrickMeta::constant
inline constexpr std::uint32_t kKnownEntryFlags = kEntryStored | kEntryConstant;
inline constexpr std::uint64_t kIndexEntrySize = 40;

/// Bytes per finest metadata block in the raw metadata section (f64 min, f64 max, u32 bits).
inline constexpr std::uint64_t kMetaEntrySize = 20;

constexpr std::uint64_t header_size_for(std::uint32_t channels, std::uint32_t flags) noexcept {
  return hdr::fixed_size + 16u * std::uint64_t(channels) + ((flags & kFlagOrigin) != 0 ? 24u : 0u) +
         ((flags & kFlagBrickErrors) != 0 ? kErrorFieldsSize : 0u);
}

/// Header offset of the errors section's fields (with kFlagBrickErrors): after the ranges and
/// the origin.
constexpr std::uint64_t error_fields_at(std::uint32_t channels, std::uint32_t flags) noexcept {
  return hdr::ranges + 16u * std::uint64_t(channels) + ((flags & kFlagOrigin) != 0 ? 24u : 0u);
}

struct StoreHeader {
  VolumeDesc volume;
  BrickLayout layout;
  std::uint32_t flags = 0;
  Codec codec = Codec::lz4;
  std::int32_t codec_level = 0;
  std::uint32_t metadata_block = 16;
  std::uint32_t level_count = 0;
  std::uint64_t bricks_per_channel = 0;
  std::uint64_t payload_offset = 0;
  std::uint64_t payload_size = 0;
  std::uint64_t index_offset = 0;
  std::uint64_t index_size = 0;
  std::uint64_t metadata_offset = 0;
  std::uint64_t metadata_size = 0;
  std::uint64_t metadata_raw_size = 0;
  std::uint32_t index_crc = 0;
  std::uint32_t metadata_crc = 0;
  // The errors section (only with kFlagBrickErrors); its raw size is index_size / 40 * 4.
  std::uint64_t errors_offset = 0;
  std::uint64_t errors_size = 0;
  std::uint32_t errors_crc = 0;
};

/// Where a brick's voxels are and what they hold. A brick whose voxels are all bitwise equal
/// has no payload; `fill_bits` then holds that voxel (zero-extended little-endian bits).
struct IndexEntry {
  std::uint64_t offset = 0;  ///< absolute file offset of the payload
  std::uint32_t size = 0;    ///< compressed payload bytes
  std::uint32_t crc = 0;     ///< CRC-32 of the compressed payload
  double min = 0.0;
  double max = 0.0;
  std::uint32_t flags = 0;
  std::uint32_t fill_bits = 0;
};

/// The encoded header (header_size_for(channels, flags) bytes, CRC included).
std::vector<std::byte> encode_header(const StoreHeader& h);

/// Reads and validates the header of `file` (magic, size, CRC, version, every field, section
/// bounds against the file size, agreement with the hierarchy the fields describe). Throws
/// resoct::Error with the code of the first problem found and the offending byte offset.
StoreHeader decode_header(const RandomAccessFile& file);

void encode_index_entry(const IndexEntry& e, std::span<std::byte, kIndexEntrySize> out);
IndexEntry decode_index_entry(std::span<const std::byte, kIndexEntrySize> in);

/// Raw (uncompressed) metadata section: per channel, the finest pyramid level as all minima
/// (f64), then all maxima (f64), then all occupancy words (u32).
std::vector<std::byte> encode_metadata(const MetadataPyramid& p);
/// Fills the finest level of `p` (already sized for the volume) from raw metadata bytes; throws
/// file_error(corrupt, ...) at `offset` when the size does not match.
void decode_metadata(std::span<const std::byte> raw, MetadataPyramid& p, const std::string& file,
                     std::uint64_t offset);

/// Raw (uncompressed) errors section: one little-endian f32 per brick and channel, index order.
std::vector<std::byte> encode_errors(std::span<const float> errors);
/// The errors of a raw errors section, one per index entry (`count`); throws
/// file_error(corrupt, ...) at `offset` for a wrong size or an error outside [0, 1] (NaN
/// included), naming the entry.
std::vector<float> decode_errors(std::span<const std::byte> raw, std::uint64_t count,
                                 const std::string& file, std::uint64_t offset);

}  // namespace resoct::detail
