#pragma once
/// \file
/// resoct's own brick store file (".rbs"): every brick of every level and channel, compressed
/// individually with LZ4 or zstd, with a brick index, per-brick metadata, a level-0 metadata
/// pyramid and CRC-32 checksums throughout. Layout: docs/brick-store-format.md.

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/sources/brick_source.hpp"
#include "resoct/io/storage/codec.hpp"
#include "resoct/base/random_access_file.hpp"

namespace resoct {

/// How write_brick_store() encodes a store.
struct StoreWriteOptions {
  Codec codec = Codec::lz4;
  int level = 0;                      ///< codec level; 0 = the codec's default (see Codec)
  std::uint32_t metadata_block = 16;  ///< level-0 voxels per metadata block edge (power of 2)
  std::uint32_t threads = 0;          ///< worker threads reading and compressing; 0 = hardware
  /// Store every brick's down-sampling error (BrickSource::brick_error of the source, measured
  /// on the worker threads), so that error-bounded LOD (Scene::lod_error_color) reads it from
  /// the store instead of measuring each coarse brick as it loads. Measuring reads the level-0
  /// bricks under every coarse brick of levels 1-3 again (coarser ones, constant and empty
  /// regions are bounded from metadata), so a conversion takes about that many extra passes
  /// over level 0 (docs/brick-store-format.md "Errors section").
  bool brick_errors = false;
  /// Called on the calling thread after each brick is written (done of total bricks, all levels
  /// and channels). May be empty.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

/// Per-level numbers of a store, summed over channels.
struct StoreLevelStats {
  glm::u64vec3 extent{0};                ///< level voxels per axis
  glm::uvec3 bricks{0};                  ///< bricks per axis (one channel)
  std::uint64_t brick_count = 0;         ///< bricks of all channels
  std::uint64_t constant_bricks = 0;     ///< bricks stored as one value (every voxel bitwise equal)
  std::uint64_t empty_bricks = 0;        ///< bricks whose voxels are all zero (BrickMeta::all_zero)
  std::uint64_t compressed_bytes = 0;    ///< payload bytes in the file
  std::uint64_t uncompressed_bytes = 0;  ///< padded voxel bytes of all bricks, constant ones too
  /// The largest and the mean stored down-sampling error of the level's bricks (0 for level 0);
  /// both 0 when the store holds no errors (StoreStats::brick_errors).
  double max_error = 0.0;
  double mean_error = 0.0;

  /// uncompressed_bytes / compressed_bytes (infinity when nothing needed a payload).
  double compression_ratio() const noexcept;
  /// empty_bricks / brick_count.
  double empty_fraction() const noexcept;
};

/// What a store holds, per level; the basis of `resoct-info`.
struct StoreStats {
  std::vector<StoreLevelStats> levels;  ///< level 0 (finest) first
  Codec codec = Codec::lz4;
  int codec_level = 0;
  std::uint32_t format_version = 0;
  std::uint64_t file_bytes = 0;
  bool brick_errors = false;  ///< the store holds every brick's down-sampling error

  /// Sum over all levels (errors: the largest, and the mean over all bricks).
  StoreLevelStats total() const noexcept;
};

/// Result of write_brick_store().
struct StoreSummary {
  StoreStats stats;
  double seconds = 0.0;  ///< wall-clock time of the whole write
};

/// Writes every brick of every level and channel of `src` to a brick store at `path`. Bricks are
/// read and compressed by `options.threads` workers and written in a fixed order, so the file
/// does not depend on the thread count. The level-0 metadata pyramid is built from the level-0
/// bricks as they pass. The file appears at `path` only when complete (temporary file, fsync,
/// rename); on any exception, including one thrown by `src`, nothing is left at `path` (an
/// existing file there is untouched) and the temporary file is removed. Throws
/// invalid_parameter for bad options, Error(io) when the file cannot be written, and rethrows
/// the first exception of the source.
StoreSummary write_brick_store(const BrickSource& src, const std::string& path,
                               const StoreWriteOptions& options = {});

/// A brick source reading a brick store file. Opening validates the header, the whole brick
/// index and the metadata section (magic, version, checksums, field sanity, every payload
/// range inside the file); read_brick() then verifies each payload's checksum and size.
/// Thread-safety: all member functions may be called from any number of threads at once
/// (reads use pread or independent HTTP requests; nothing shares a file position).
class BrickStoreSource final : public BrickSource {
 public:
  /// Opens and validates `path`. Throws resoct::Error with a code per failure class (io,
  /// truncated, bad_magic, unsupported_version, checksum_mismatch, out_of_range, corrupt,
  /// overflow, unsupported, size_mismatch, decompress_failed) and a message naming the file and
  /// the byte offset.
  explicit BrickStoreSource(const std::string& path);
  /// Opens and validates a store read through `file` (a local file, or an HTTP object read by
  /// Range requests: open_random_access_file()); name() is then file->path(). Throws as above,
  /// naming file->path(), and Error(invalid_argument) naming "file" when it is null.
  explicit BrickStoreSource(std::unique_ptr<RandomAccessFile> file);
  ~BrickStoreSource() override;
  BrickStoreSource(const BrickStoreSource&) = delete;
  BrickStoreSource& operator=(const BrickStoreSource&) = delete;

  const BrickHierarchy& hierarchy() const override;
  /// Reads, checks (CRC-32, decoded size) and decompresses one brick. Throws
  /// Error(checksum_mismatch | decompress_failed | size_mismatch) naming the file and the
  /// payload offset when the payload is damaged.
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  /// From the index; touches no payload.
  BrickMeta brick_meta(BrickKey key) const override;
  /// The stored error when the store holds errors (stats().brick_errors); else measured
  /// (BrickSource::brick_error).
  double brick_error(BrickKey key, std::span<const std::byte> padded) const override;
  /// From the stored level-0 metadata pyramid. Throws invalid_parameter for a bad channel.
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override;
  /// The path or URL the store was opened from.
  std::string name() const override;

  /// Per-level statistics, computed from the index at open.
  const StoreStats& stats() const noexcept;
  /// Metadata block edge of the stored pyramid, in level-0 voxels.
  std::uint32_t metadata_block() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace resoct
