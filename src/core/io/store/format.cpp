#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "resoct/io/storage/checksum.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/store/format.hpp"

namespace resoct::detail {

namespace {
void put_u32(std::span<std::byte> b, std::uint64_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = std::byte((v >> (8 * i)) & 0xFFu);
}
void put_u64(std::span<std::byte> b, std::uint64_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b[at + i] = std::byte((v >> (8 * i)) & 0xFFu);
}
void put_f64(std::span<std::byte> b, std::uint64_t at, double v) {
  put_u64(b, at, std::bit_cast<std::uint64_t>(v));
}
std::uint32_t get_u32(std::span<const std::byte> b, std::uint64_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t(b[at + i]) << (8 * i);
  return v;
}
std::uint64_t get_u64(std::span<const std::byte> b, std::uint64_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(b[at + i]) << (8 * i);
  return v;
}
double get_f64(std::span<const std::byte> b, std::uint64_t at) {
  return std::bit_cast<double>(get_u64(b, at));
}

// Any future version keeps magic, version and header_size in the first 16 bytes and the CRC in
// the header's last 4 bytes; this bound only keeps a corrupt size from causing a huge read.
constexpr std::uint64_t kMaxHeaderSize = std::uint64_t(1) << 20;
// zstd cannot expand data by more than this: a block holds at most 128 KiB and an RLE block
// costs at least 4 bytes. A larger claimed raw size is corrupt, so it is never allocated.
constexpr std::uint64_t kMaxZstdRatio = (std::uint64_t(128) << 10) / 4;

bool mul_overflows(std::uint64_t a, std::uint64_t b, std::uint64_t& out) {
  return __builtin_mul_overflow(a, b, &out);
}

std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) {
  return a / b + (a % b != 0);
}

struct Section {
  const char* name;
  std::uint64_t field;  // header offset of the section's offset field
  std::uint64_t offset;
  std::uint64_t size;
};
}  // namespace

std::vector<std::byte> encode_header(const StoreHeader& h) {
  const std::uint32_t channels = h.volume.channels;
  std::vector<std::byte> b(header_size_for(channels, h.flags));
  for (std::size_t i = 0; i < kStoreMagic.size(); ++i) b[i] = std::byte(kStoreMagic[i]);
  put_u32(b, hdr::version, kStoreVersion);
  put_u32(b, hdr::header_size, std::uint32_t(b.size()));
  put_u32(b, hdr::flags, h.flags);
  put_u32(b, hdr::voxel_type, std::uint32_t(h.volume.type));
  for (int i = 0; i < 3; ++i) {
    put_u64(b, hdr::extent + 8u * i, h.volume.extent[i]);
    put_f64(b, hdr::spacing + 8u * i, h.volume.spacing[i]);
    put_u32(b, hdr::brick_size + 4u * i, h.layout.brick_size[i]);
  }
  put_u32(b, hdr::channels, channels);
  put_u32(b, hdr::halo, h.layout.halo);
  put_u32(b, hdr::codec, std::uint32_t(h.codec));
  put_u32(b, hdr::codec_level, std::bit_cast<std::uint32_t>(h.codec_level));
  put_u32(b, hdr::metadata_block, h.metadata_block);
  put_u32(b, hdr::level_count, h.level_count);
  put_u32(b, hdr::index_crc, h.index_crc);
  put_u64(b, hdr::bricks_per_channel, h.bricks_per_channel);
  put_u64(b, hdr::payload_offset, h.payload_offset);
  put_u64(b, hdr::payload_size, h.payload_size);
  put_u64(b, hdr::index_offset, h.index_offset);
  put_u64(b, hdr::index_size, h.index_size);
  put_u64(b, hdr::metadata_offset, h.metadata_offset);
  put_u64(b, hdr::metadata_size, h.metadata_size);
  put_u64(b, hdr::metadata_raw_size, h.metadata_raw_size);
  put_u32(b, hdr::metadata_crc, h.metadata_crc);
  put_u32(b, hdr::data_type, h.volume.data_type ? std::uint32_t(*h.volume.data_type) : 0u);
  for (std::uint32_t c = 0; c < channels; ++c) {
    const ValueRange r = h.volume.range(c);
    put_f64(b, hdr::ranges + 16u * c, r.lo);
    put_f64(b, hdr::ranges + 16u * c + 8u, r.hi);
  }
  if ((h.flags & kFlagOrigin) != 0) {
    for (int i = 0; i < 3; ++i)
      put_f64(b, hdr::ranges + 16u * channels + 8u * i, h.volume.origin[i]);
  }
  if ((h.flags & kFlagBrickErrors) != 0) {
    const std::uint64_t at = error_fields_at(channels, h.flags);
    put_u64(b, at + kErrorFieldOffset, h.errors_offset);
    put_u64(b, at + kErrorFieldSize, h.errors_size);
    put_u32(b, at + kErrorFieldCrc, h.errors_crc);
    put_u32(b, at + kErrorFieldReserved, 0u);
  }
  const std::uint64_t crc_at = b.size() - 4;
  put_u32(b, crc_at, crc32(std::span<const std::byte>(b).first(crc_at)));
  return b;
}

StoreHeader decode_header(const RandomAccessFile& file) {
  const std::string& path = file.path();
  const std::uint64_t fsize = file.size();
  auto fail = [&](ErrorCode code, std::uint64_t at, const std::string& what) {
    return file_error(code, path, at, what);
  };
  if (fsize < 16) {
    // Still tell a foreign short file from a cut-off store.
    std::array<std::byte, 8> m{};
    const std::size_t n = std::size_t(std::min<std::uint64_t>(fsize, 8));
    file.read_at(0, std::span<std::byte>(m).first(n));
    for (std::size_t i = 0; i < n; ++i) {
      if (m[i] != std::byte(kStoreMagic[i])) {
        throw fail(ErrorCode::bad_magic, i, "not a resoct brick store (wrong magic)");
      }
    }
    throw fail(ErrorCode::truncated, fsize,
               "file has " + std::to_string(fsize) + " bytes, a brick store header needs more");
  }
  std::array<std::byte, 16> head{};
  file.read_at(0, head);
  for (std::size_t i = 0; i < kStoreMagic.size(); ++i) {
    if (head[i] != std::byte(kStoreMagic[i])) {
      throw fail(ErrorCode::bad_magic, i, "not a resoct brick store (wrong magic)");
    }
  }
  const std::uint64_t hs = get_u32(head, hdr::header_size);
  if (hs < 20 || hs > kMaxHeaderSize) {
    throw fail(ErrorCode::corrupt, hdr::header_size,
               "header size " + std::to_string(hs) + " is impossible");
  }
  if (hs > fsize) {
    throw fail(ErrorCode::truncated, fsize,
               "file ends inside the " + std::to_string(hs) + "-byte header");
  }
  std::vector<std::byte> b(hs);
  file.read_at(0, b);
  const std::uint32_t stored_crc = get_u32(b, hs - 4);
  const std::uint32_t crc = crc32(std::span<const std::byte>(b).first(hs - 4));
  if (crc != stored_crc) {
    throw fail(ErrorCode::checksum_mismatch, hs - 4,
               "header checksum mismatch (stored " + std::to_string(stored_crc) + ", computed " +
                   std::to_string(crc) + ")");
  }
  const std::uint32_t version = get_u32(b, hdr::version);
  if (version != kStoreVersion) {
    throw fail(ErrorCode::unsupported_version, hdr::version,
               "format version " + std::to_string(version) + " (this build reads version " +
                   std::to_string(kStoreVersion) + ")");
  }

  StoreHeader h;
  h.flags = get_u32(b, hdr::flags);
  if ((h.flags & ~kKnownFlags) != 0) {
    throw fail(ErrorCode::unsupported, hdr::flags,
               "unknown header flags " + std::to_string(h.flags & ~kKnownFlags));
  }
  const std::uint32_t channels = get_u32(b, hdr::channels);
  if (channels == 0 || channels > kMaxChannels) {
    throw fail(ErrorCode::corrupt, hdr::channels,
               "channel count " + std::to_string(channels) + " outside 1.." +
                   std::to_string(kMaxChannels));
  }
  if (hs != header_size_for(channels, h.flags)) {
    throw fail(ErrorCode::corrupt, hdr::header_size,
               "header size " + std::to_string(hs) + " does not match " + std::to_string(channels) +
                   " channels");
  }
  h.volume.channels = channels;
  const std::uint32_t type = get_u32(b, hdr::voxel_type);
  if (type > std::uint32_t(VoxelType::f32)) {
    throw fail(ErrorCode::corrupt, hdr::voxel_type, "unknown voxel type " + std::to_string(type));
  }
  h.volume.type = VoxelType(type);
  if (const std::uint32_t dt = get_u32(b, hdr::data_type); dt != 0) {
    if (dt < std::uint32_t(DataType::i8) || dt > std::uint32_t(DataType::f64) ||
        data_mapping(DataType(dt)).stored != h.volume.type) {
      throw fail(ErrorCode::corrupt, hdr::data_type,
                 "data type " + std::to_string(dt) + " is not one kept as voxel type " +
                     std::string(to_string(h.volume.type)));
    }
    h.volume.data_type = DataType(dt);
  }
  const char* axis = "xyz";
  for (int i = 0; i < 3; ++i) {
    h.volume.extent[i] = get_u64(b, hdr::extent + 8u * i);
    if (h.volume.extent[i] == 0) {
      throw fail(ErrorCode::corrupt, hdr::extent + 8u * i,
                 std::string("extent.") + axis[i] + " is zero");
    }
    h.volume.spacing[i] = get_f64(b, hdr::spacing + 8u * i);
    if (!(std::isfinite(h.volume.spacing[i]) && h.volume.spacing[i] > 0.0)) {
      throw fail(ErrorCode::corrupt, hdr::spacing + 8u * i,
                 std::string("spacing.") + axis[i] + " is not a positive finite number");
    }
    h.layout.brick_size[i] = get_u32(b, hdr::brick_size + 4u * i);
    if (h.layout.brick_size[i] < 4 || h.layout.brick_size[i] > 1024) {
      throw fail(ErrorCode::corrupt, hdr::brick_size + 4u * i,
                 std::string("brick_size.") + axis[i] + " = " +
                     std::to_string(h.layout.brick_size[i]) + " outside 4..1024");
    }
  }
  std::uint64_t voxels = 0, bytes = 0;
  if (mul_overflows(h.volume.extent.x, h.volume.extent.y, voxels) ||
      mul_overflows(voxels, h.volume.extent.z, voxels) ||
      mul_overflows(voxels, std::uint64_t(channels) * voxel_size(h.volume.type), bytes)) {
    throw fail(ErrorCode::overflow, hdr::extent,
               "extent " + std::to_string(h.volume.extent.x) + "x" +
                   std::to_string(h.volume.extent.y) + "x" + std::to_string(h.volume.extent.z) +
                   ": voxel or byte count overflows 64 bits");
  }
  h.layout.halo = get_u32(b, hdr::halo);
  if (h.layout.halo > 4) {
    throw fail(ErrorCode::corrupt, hdr::halo, "halo " + std::to_string(h.layout.halo) + " > 4");
  }
  const std::uint32_t codec = get_u32(b, hdr::codec);
  if (codec > std::uint32_t(Codec::zstd)) {
    throw fail(ErrorCode::corrupt, hdr::codec, "unknown codec " + std::to_string(codec));
  }
  h.codec = Codec(codec);
  h.codec_level = std::bit_cast<std::int32_t>(get_u32(b, hdr::codec_level));
  try {
    validate_codec_level(h.codec, h.codec_level);
  } catch (const Error& e) {
    throw fail(ErrorCode::corrupt, hdr::codec_level, e.what());
  }
  h.metadata_block = get_u32(b, hdr::metadata_block);
  const std::uint32_t mb = h.metadata_block;
  if (mb < 4 || mb > 1024 || (mb & (mb - 1)) != 0) {
    throw fail(ErrorCode::corrupt, hdr::metadata_block,
               "metadata block " + std::to_string(mb) + " is not a power of two in 4..1024");
  }
  for (std::uint32_t c = 0; c < channels; ++c) {
    const ValueRange r{get_f64(b, hdr::ranges + 16u * c), get_f64(b, hdr::ranges + 16u * c + 8u)};
    if (!(std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo < r.hi)) {
      throw fail(ErrorCode::corrupt, hdr::ranges + 16u * c,
                 "value range of channel " + std::to_string(c) + " is not finite lo < hi");
    }
    h.volume.ranges.push_back(r);
  }
  if ((h.flags & kFlagDefaultRanges) != 0) h.volume.ranges.clear();
  if ((h.flags & kFlagOrigin) != 0) {
    for (int i = 0; i < 3; ++i) {
      const std::uint64_t at = hdr::ranges + 16u * channels + 8u * i;
      h.volume.origin[i] = get_f64(b, at);
      if (!std::isfinite(h.volume.origin[i])) {
        throw fail(ErrorCode::corrupt, at, std::string("origin.") + "xyz"[i] + " is not finite");
      }
    }
  }

  // The hierarchy rejects volumes whose brick coordinates do not fit a brick key.
  std::uint64_t bpc = 0;
  std::uint32_t levels = 0;
  try {
    const BrickHierarchy hier(h.volume, h.layout);
    bpc = hier.bricks_per_channel();
    levels = hier.level_count();
  } catch (const Error& e) {
    throw fail(e.code() == ErrorCode::overflow ? ErrorCode::overflow : ErrorCode::corrupt,
               hdr::extent, std::string("volume and brick layout are unusable: ") + e.what());
  }
  h.level_count = get_u32(b, hdr::level_count);
  if (h.level_count != levels) {
    throw fail(ErrorCode::corrupt, hdr::level_count,
               "level count " + std::to_string(h.level_count) + ", the volume has " +
                   std::to_string(levels));
  }
  h.bricks_per_channel = get_u64(b, hdr::bricks_per_channel);
  if (h.bricks_per_channel != bpc) {
    throw fail(ErrorCode::corrupt, hdr::bricks_per_channel,
               "bricks per channel " + std::to_string(h.bricks_per_channel) + ", the volume has " +
                   std::to_string(bpc));
  }
  h.index_crc = get_u32(b, hdr::index_crc);
  h.metadata_crc = get_u32(b, hdr::metadata_crc);
  h.payload_offset = get_u64(b, hdr::payload_offset);
  h.payload_size = get_u64(b, hdr::payload_size);
  h.index_offset = get_u64(b, hdr::index_offset);
  h.index_size = get_u64(b, hdr::index_size);
  h.metadata_offset = get_u64(b, hdr::metadata_offset);
  h.metadata_size = get_u64(b, hdr::metadata_size);
  h.metadata_raw_size = get_u64(b, hdr::metadata_raw_size);

  std::uint64_t want_index = 0;
  if (mul_overflows(bpc * channels, kIndexEntrySize, want_index)) {
    throw fail(ErrorCode::overflow, hdr::index_size, "index size overflows 64 bits");
  }
  if (h.index_size != want_index) {
    throw fail(
        ErrorCode::corrupt, hdr::index_size,
        "index size " + std::to_string(h.index_size) + ", expected " + std::to_string(want_index));
  }
  std::uint64_t blocks = 1, want_meta = 0;
  for (int i = 0; i < 3; ++i) {
    // Cannot overflow: the voxel count above fits in 64 bits and every factor is <= extent.
    blocks *= std::max<std::uint64_t>(1, ceil_div(h.volume.extent[i], mb));
  }
  if (mul_overflows(blocks, std::uint64_t(channels) * kMetaEntrySize, want_meta)) {
    throw fail(ErrorCode::overflow, hdr::metadata_raw_size, "metadata size overflows 64 bits");
  }
  if (h.metadata_raw_size != want_meta) {
    throw fail(ErrorCode::corrupt, hdr::metadata_raw_size,
               "metadata raw size " + std::to_string(h.metadata_raw_size) + ", expected " +
                   std::to_string(want_meta));
  }
  if (h.metadata_size == 0 || h.metadata_raw_size / kMaxZstdRatio > h.metadata_size) {
    throw fail(ErrorCode::corrupt, hdr::metadata_size,
               "compressed metadata size " + std::to_string(h.metadata_size) + " cannot hold " +
                   std::to_string(h.metadata_raw_size) + " bytes");
  }

  const std::uint64_t ef = error_fields_at(channels, h.flags);
  int section_count = 3;
  if ((h.flags & kFlagBrickErrors) != 0) {
    section_count = 4;
    h.errors_offset = get_u64(b, ef + kErrorFieldOffset);
    h.errors_size = get_u64(b, ef + kErrorFieldSize);
    h.errors_crc = get_u32(b, ef + kErrorFieldCrc);
    if (get_u32(b, ef + kErrorFieldReserved) != 0) {
      throw fail(ErrorCode::corrupt, ef + kErrorFieldReserved,
                 "reserved word of the errors section fields is not zero");
    }
    // Cannot overflow: the index size (40 bytes per entry) fits in 64 bits.
    const std::uint64_t raw = h.index_size / kIndexEntrySize * kErrorEntrySize;
    if (h.errors_size == 0 || raw / kMaxZstdRatio > h.errors_size) {
      throw fail(ErrorCode::corrupt, ef + kErrorFieldSize,
                 "compressed errors size " + std::to_string(h.errors_size) + " cannot hold " +
                     std::to_string(raw) + " bytes");
    }
  }
  const Section sections[4] = {
      {"payload", hdr::payload_offset, h.payload_offset, h.payload_size},
      {"index", hdr::index_offset, h.index_offset, h.index_size},
      {"metadata", hdr::metadata_offset, h.metadata_offset, h.metadata_size},
      {"errors", ef + kErrorFieldOffset, h.errors_offset, h.errors_size},
  };
  for (int i = 0; i < section_count; ++i) {
    const Section& s = sections[i];
    std::uint64_t end = 0;
    if (__builtin_add_overflow(s.offset, s.size, &end) || s.offset < hs) {
      throw fail(ErrorCode::corrupt, s.field,
                 std::string(s.name) + " section [" + std::to_string(s.offset) + ", +" +
                     std::to_string(s.size) + ") is impossible");
    }
    if (end > fsize) {
      throw fail(ErrorCode::truncated, fsize,
                 std::string("file ends before the end of the ") + s.name + " section (" +
                     std::to_string(end) + ", header field at offset " + std::to_string(s.field) +
                     ")");
    }
  }
  for (int i = 0; i < section_count; ++i) {
    for (int j = i + 1; j < section_count; ++j) {
      const Section& a = sections[i];
      const Section& c = sections[j];
      if (a.offset < c.offset + c.size && c.offset < a.offset + a.size) {
        throw fail(ErrorCode::corrupt, c.field,
                   std::string(a.name) + " and " + c.name + " sections overlap");
      }
    }
  }
  return h;
}

void encode_index_entry(const IndexEntry& e, std::span<std::byte, kIndexEntrySize> out) {
  put_u64(out, 0, e.offset);
  put_u32(out, 8, e.size);
  put_u32(out, 12, e.crc);
  put_f64(out, 16, e.min);
  put_f64(out, 24, e.max);
  put_u32(out, 32, e.flags);
  put_u32(out, 36, e.fill_bits);
}

IndexEntry decode_index_entry(std::span<const std::byte, kIndexEntrySize> in) {
  IndexEntry e;
  e.offset = get_u64(in, 0);
  e.size = get_u32(in, 8);
  e.crc = get_u32(in, 12);
  e.min = get_f64(in, 16);
  e.max = get_f64(in, 24);
  e.flags = get_u32(in, 32);
  e.fill_bits = get_u32(in, 36);
  return e;
}

std::vector<std::byte> encode_metadata(const MetadataPyramid& p) {
  const std::size_t n = p.finest(0).size();
  std::vector<std::byte> b(std::size_t(p.channels()) * n * kMetaEntrySize);
  std::size_t off = 0;
  // Structure of arrays: similar values sit together, which zstd compresses far better.
  for (std::uint32_t c = 0; c < p.channels(); ++c) {
    const std::span<const RegionMeta> f = p.finest(c);
    for (const RegionMeta& m : f) put_f64(b, (off += 8) - 8, m.min);
    for (const RegionMeta& m : f) put_f64(b, (off += 8) - 8, m.max);
    for (const RegionMeta& m : f) put_u32(b, (off += 4) - 4, m.occupancy);
  }
  return b;
}

void decode_metadata(std::span<const std::byte> raw, MetadataPyramid& p, const std::string& file,
                     std::uint64_t offset) {
  const std::size_t n = p.finest(0).size();
  if (raw.size() != std::size_t(p.channels()) * n * kMetaEntrySize) {
    throw file_error(ErrorCode::corrupt, file, offset,
                     "metadata holds " + std::to_string(raw.size()) + " bytes, expected " +
                         std::to_string(std::size_t(p.channels()) * n * kMetaEntrySize));
  }
  std::size_t off = 0;
  for (std::uint32_t c = 0; c < p.channels(); ++c) {
    const std::span<RegionMeta> f = p.finest(c);
    for (RegionMeta& m : f) m.min = get_f64(raw, (off += 8) - 8);
    for (RegionMeta& m : f) m.max = get_f64(raw, (off += 8) - 8);
    for (RegionMeta& m : f) m.occupancy = get_u32(raw, (off += 4) - 4);
  }
}

std::vector<std::byte> encode_errors(std::span<const float> errors) {
  std::vector<std::byte> b(errors.size() * kErrorEntrySize);
  for (std::size_t i = 0; i < errors.size(); ++i) {
    put_u32(b, i * kErrorEntrySize, std::bit_cast<std::uint32_t>(errors[i]));
  }
  return b;
}

std::vector<float> decode_errors(std::span<const std::byte> raw, std::uint64_t count,
                                 const std::string& file, std::uint64_t offset) {
  if (raw.size() != count * kErrorEntrySize) {
    throw file_error(ErrorCode::corrupt, file, offset,
                     "errors section holds " + std::to_string(raw.size()) + " bytes, expected " +
                         std::to_string(count * kErrorEntrySize));
  }
  std::vector<float> out(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = std::bit_cast<float>(get_u32(raw, i * kErrorEntrySize));
    if (!(out[i] >= 0.0f && out[i] <= 1.0f)) {
      throw file_error(ErrorCode::corrupt, file, offset,
                       "errors section: the error of brick index entry " + std::to_string(i) +
                           " is " + std::to_string(out[i]) + ", outside [0, 1]");
    }
  }
  return out;
}

}  // namespace resoct::detail
