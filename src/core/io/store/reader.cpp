#include <algorithm>
#include <cstring>
#include <new>
#include <string>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/storage/checksum.hpp"
#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/sources/metadata_pyramid.hpp"
#include "resoct/io/store/format.hpp"

namespace resoct {

using detail::IndexEntry;
using detail::StoreHeader;

struct BrickStoreSource::Impl {
  Impl(std::unique_ptr<RandomAccessFile> f, const StoreHeader& h)
      : file_ptr(std::move(f)),
        file(*file_ptr),
        header(h),
        hierarchy(h.volume, h.layout),
        pyramid(h.volume.extent, h.metadata_block, h.volume.channels) {}

  std::unique_ptr<RandomAccessFile> file_ptr;
  const RandomAccessFile& file;  // a local file or an HTTP object (Range requests)
  StoreHeader header;
  BrickHierarchy hierarchy;
  std::vector<IndexEntry> index;  // channel-major, then BrickHierarchy::linear_index
  std::vector<float> errors;      // per index entry; empty without kFlagBrickErrors
  MetadataPyramid pyramid;
  StoreStats stats;

  std::size_t slot(BrickKey key) const {
    return std::size_t(std::uint64_t(key.channel()) * hierarchy.bricks_per_channel() +
                       hierarchy.linear_index(key.level(), key.brick()));
  }
  const IndexEntry& entry(BrickKey key) const { return index[slot(key)]; }
  // The compressed bytes of a section (inside the file: checked at open), CRC-checked.
  std::vector<std::byte> read_section(std::uint64_t offset, std::uint64_t size,
                                      std::uint32_t want_crc, const char* what) const {
    std::vector<std::byte> packed(static_cast<std::size_t>(size));
    file.read_at(offset, packed);
    const std::uint32_t crc = crc32(packed);
    if (crc != want_crc) {
      throw file_error(ErrorCode::checksum_mismatch, file.path(), offset,
                       std::string(what) + " checksum mismatch (stored " +
                           std::to_string(want_crc) + ", computed " + std::to_string(crc) + ")");
    }
    return packed;
  }
  void load_index();
  void load_metadata();
  void load_errors();
  void compute_stats();
};

namespace {
// Fill bits must be a voxel of the store's type; wider values can only come from corruption.
bool fill_fits(std::uint32_t bits, VoxelType t) {
  return t == VoxelType::u8 ? bits <= 0xFFu : t == VoxelType::u16 ? bits <= 0xFFFFu : true;
}

bool plausible_range(double lo, double hi) {
  // An all-NaN brick reports +inf / -inf; anything else must be an ordered pair.
  return lo <= hi || (lo == std::numeric_limits<double>::infinity() &&
                      hi == -std::numeric_limits<double>::infinity());
}
}  // namespace

void BrickStoreSource::Impl::load_index() {
  const std::string& path = file.path();
  const StoreHeader& h = header;
  std::vector<std::byte> bytes(std::size_t(h.index_size));  // bounded by the file size
  file.read_at(h.index_offset, bytes);
  const std::uint32_t crc = crc32(bytes);
  if (crc != h.index_crc) {
    throw file_error(ErrorCode::checksum_mismatch, path, h.index_offset,
                     "brick index checksum mismatch (stored " + std::to_string(h.index_crc) +
                         ", computed " + std::to_string(crc) + ")");
  }
  const std::uint64_t brick_bytes = h.layout.padded_voxels() * voxel_size(h.volume.type);
  const std::uint64_t max_payload = compress_bound(h.codec, std::size_t(brick_bytes));
  const std::uint64_t payload_end = h.payload_offset + h.payload_size;
  const std::uint64_t count = h.index_size / detail::kIndexEntrySize;
  index.resize(std::size_t(count));
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint64_t at = h.index_offset + i * detail::kIndexEntrySize;
    const IndexEntry e =
        detail::decode_index_entry(std::span<const std::byte, detail::kIndexEntrySize>(
            bytes.data() + i * detail::kIndexEntrySize, detail::kIndexEntrySize));
    const std::string which = "brick index entry " + std::to_string(i);
    if ((e.flags & ~detail::kKnownEntryFlags) != 0) {
      throw file_error(ErrorCode::corrupt, path, at + 32, which + ": unknown flags");
    }
    if (!plausible_range(e.min, e.max)) {
      throw file_error(ErrorCode::corrupt, path, at + 16, which + ": min/max not ordered");
    }
    if ((e.flags & detail::kEntryStored) != 0) {
      if (e.size == 0 || e.size > max_payload) {
        throw file_error(ErrorCode::corrupt, path, at + 8,
                         which + ": payload size " + std::to_string(e.size) + " impossible for a " +
                             std::to_string(brick_bytes) + "-byte brick");
      }
      if (e.offset < h.payload_offset || e.offset > payload_end ||
          e.size > payload_end - e.offset) {
        throw file_error(ErrorCode::out_of_range, path, at,
                         which + ": payload [" + std::to_string(e.offset) + ", +" +
                             std::to_string(e.size) + ") outside the payload section [" +
                             std::to_string(h.payload_offset) + ", " + std::to_string(payload_end) +
                             ")");
      }
    } else if (e.size != 0 || e.offset != 0 || !fill_fits(e.fill_bits, h.volume.type)) {
      throw file_error(ErrorCode::corrupt, path, at,
                       which + ": constant brick with a payload or an oversized value");
    }
    index[std::size_t(i)] = e;
  }
}

void BrickStoreSource::Impl::load_metadata() {
  const std::string& path = file.path();
  const StoreHeader& h = header;
  const std::vector<std::byte> packed =
      read_section(h.metadata_offset, h.metadata_size, h.metadata_crc, "metadata");
  // Raw size was checked against the volume and against zstd's maximum expansion.
  std::vector<std::byte> raw(std::size_t(h.metadata_raw_size));
  decompress_exact(Codec::zstd, packed, raw, path, h.metadata_offset);
  detail::decode_metadata(raw, pyramid, path, h.metadata_offset);
  pyramid.build();
}

void BrickStoreSource::Impl::load_errors() {
  const StoreHeader& h = header;
  if ((h.flags & detail::kFlagBrickErrors) == 0) return;
  const std::string& path = file.path();
  const std::vector<std::byte> packed =
      read_section(h.errors_offset, h.errors_size, h.errors_crc, "errors section");
  // The raw size follows from the index, which was checked against the volume; its ratio to the
  // stored bytes was checked against zstd's maximum expansion.
  std::vector<std::byte> raw(index.size() * detail::kErrorEntrySize);
  decompress_exact(Codec::zstd, packed, raw, path, h.errors_offset);
  errors = detail::decode_errors(raw, index.size(), path, h.errors_offset);
}

void BrickStoreSource::Impl::compute_stats() {
  const std::uint64_t brick_bytes = header.layout.padded_voxels() * voxel_size(header.volume.type);
  stats.codec = header.codec;
  stats.codec_level = header.codec_level;
  stats.format_version = detail::kStoreVersion;
  stats.file_bytes = file.size();
  stats.brick_errors = !errors.empty();
  stats.levels.resize(hierarchy.level_count());
  const std::uint64_t bpc = hierarchy.bricks_per_channel();
  for (std::uint32_t l = 0; l < hierarchy.level_count(); ++l) {
    const LevelInfo& li = hierarchy.level(l);
    StoreLevelStats& s = stats.levels[l];
    s.extent = li.extent;
    s.bricks = li.bricks;
    for (std::uint32_t c = 0; c < header.volume.channels; ++c) {
      for (std::uint64_t i = 0; i < li.brick_count; ++i) {
        const std::size_t at = std::size_t(c * bpc + li.first_brick + i);
        const IndexEntry& e = index[at];
        if (!errors.empty()) {
          s.max_error = std::max(s.max_error, double(errors[at]));
          s.mean_error += double(errors[at]);
        }
        s.brick_count += 1;
        s.uncompressed_bytes += brick_bytes;
        if ((e.flags & detail::kEntryStored) != 0) {
          s.compressed_bytes += e.size;
        } else {
          s.constant_bricks += 1;
        }
        if ((e.flags & detail::kEntryConstant) != 0 && e.min == 0.0 && e.max == 0.0) {
          s.empty_bricks += 1;
        }
      }
    }
    if (s.brick_count != 0) s.mean_error /= double(s.brick_count);
  }
}

BrickStoreSource::BrickStoreSource(const std::string& path)
    : BrickStoreSource(std::make_unique<ReadFile>(path)) {}

BrickStoreSource::BrickStoreSource(std::unique_ptr<RandomAccessFile> file) {
  if (!file) throw invalid_parameter("file", "must not be null");
  const std::string path = file->path();
  try {
    const StoreHeader h = detail::decode_header(*file);
    impl_ = std::make_unique<Impl>(std::move(file), h);
    impl_->load_index();
    impl_->load_metadata();
    impl_->load_errors();
    impl_->compute_stats();
  } catch (const std::bad_alloc&) {
    throw file_error(ErrorCode::out_of_memory, path, 0,
                     "not enough memory for the brick index or metadata");
  }
}

BrickStoreSource::~BrickStoreSource() = default;

const BrickHierarchy& BrickStoreSource::hierarchy() const {
  return impl_->hierarchy;
}

std::string BrickStoreSource::name() const {
  return impl_->file.path();
}

const StoreStats& BrickStoreSource::stats() const noexcept {
  return impl_->stats;
}

std::uint32_t BrickStoreSource::metadata_block() const noexcept {
  return impl_->header.metadata_block;
}

void BrickStoreSource::read_brick(BrickKey key, std::span<std::byte> out) const {
  check_brick_request(key, out);
  const IndexEntry& e = impl_->entry(key);
  const std::size_t vs = voxel_size(impl_->header.volume.type);
  if ((e.flags & detail::kEntryStored) == 0) {
    std::byte voxel[4];
    for (std::size_t i = 0; i < vs; ++i) voxel[i] = std::byte((e.fill_bits >> (8 * i)) & 0xFFu);
    for (std::size_t i = 0; i < out.size(); i += vs) std::memcpy(out.data() + i, voxel, vs);
    return;
  }
  // Per-thread staging buffer: no allocation per brick after warm-up, no sharing.
  thread_local std::vector<std::byte> packed;
  packed.resize(e.size);
  const std::string& path = impl_->file.path();
  impl_->file.read_at(e.offset, packed);
  const std::uint32_t crc = crc32(packed);
  if (crc != e.crc) {
    throw file_error(ErrorCode::checksum_mismatch, path, e.offset,
                     "payload checksum mismatch of brick (level " + std::to_string(key.level()) +
                         ", channel " + std::to_string(key.channel()) + ")");
  }
  decompress_exact(impl_->header.codec, packed, out, path, e.offset);
}

BrickMeta BrickStoreSource::brick_meta(BrickKey key) const {
  if (!impl_->hierarchy.contains(key)) {
    throw Error(ErrorCode::out_of_range, name() + ": brick_meta of a key outside the hierarchy");
  }
  const IndexEntry& e = impl_->entry(key);
  BrickMeta m;
  m.min = e.min;
  m.max = e.max;
  m.constant = (e.flags & detail::kEntryConstant) != 0;
  return m;
}

double BrickStoreSource::brick_error(BrickKey key, std::span<const std::byte> padded) const {
  if (impl_->errors.empty()) return BrickSource::brick_error(key, padded);
  check_brick_request(key, padded);
  return double(impl_->errors[impl_->slot(key)]);
}

RegionMeta BrickStoreSource::region_meta(std::uint32_t channel, const Box3& level0_region) const {
  if (channel >= impl_->header.volume.channels) {
    throw invalid_parameter("channel", std::to_string(channel) +
                                           " >= " + std::to_string(impl_->header.volume.channels) +
                                           " channels of " + name());
  }
  return impl_->pyramid.query(channel, level0_region);
}

}  // namespace resoct
