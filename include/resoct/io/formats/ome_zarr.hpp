#pragma once
/// \file
/// OME-Zarr images (NGFF 0.4 over zarr v2, NGFF 0.5 over zarr v3 with sharding; docs/formats.md)
/// as brick sources, read through a ByteStore, so the
/// same reader serves a local directory and HTTP servers.
///
/// Mapping: the spatial axes z, y, x become resoct's z, y, x (an absent one has extent 1), `c`
/// becomes channels (at most 256), `t` is the time series: the source reads the timepoint given by
/// OmeZarrOptions::timepoint, reports the extent of `t` as timepoints(), and open_timepoint(t)
/// opens another one sharing the metadata and shard indexes (decoded chunks, computed levels and
/// region metadata are per timepoint; value ranges are the opened timepoint's, kept for all).
/// Spacing is the finest
/// dataset's scale. A coarser dataset is used as hierarchy level l when its shape equals level
/// l's extent and its scale is the finest scale times 2^factor_log2 of that level (relative
/// tolerance 1e-3); every other level is built on demand from the next finer one
/// (pyramid_source.hpp), and datasets that match no level are not read. Each channel's value
/// range is its omero window when the file gives one for every channel, else its data's finite
/// min/max: one pass over the finest level at open when it is within
/// PyramidSourceOptions::eager_scan_voxels (like the metadata pass), else over the coarsest
/// stored dataset within that budget, else the type's default range. Above the budget opening
/// reads metadata objects only and region metadata is computed lazily (docs/formats.md).
///
/// Bricks are cut from chunks on demand (dynamic rebricking, Fogal et al. 2013 §5.2): decoded
/// chunks live in an LRU cache with a byte budget, so neighbouring bricks cut from one chunk
/// decode it once. A missing chunk is all fill_value. A store whose root holds a bare `.zarray`
/// (no `multiscales`) is read as one dataset with axes (c,) z, y, x by rank.

#include <cstdint>
#include <memory>
#include <string>

#include "resoct/io/storage/byte_store.hpp"
#include "resoct/io/formats/ome_multiscales.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/io/formats/zarr_array.hpp"

namespace resoct {

struct OmeZarrOptions {
  std::uint64_t timepoint = 0;                                 ///< index along `t`
  std::uint64_t chunk_cache_bytes = std::uint64_t(512) << 20;  ///< decoded chunks (LRU)
  PyramidSourceOptions pyramid;  ///< computed levels, metadata, threads
};

namespace detail {
struct ZarrImage;  // metadata, arrays and the decoded-chunk cache (zarr_source.cpp)
}

/// An opened OME-Zarr image (create it with open_ome_zarr). Thread-safety: as BrickSource.
class OmeZarrSource final : public PyramidSource {
 public:
  OmeZarrSource(std::shared_ptr<const detail::ZarrImage> image, VolumeDesc desc, BrickLayout layout,
                std::vector<LevelBoxReader> levels, std::string name, PyramidSourceOptions options,
                std::vector<int> level_dataset);

  /// The image metadata (axes, datasets, omero channel labels / colours / windows).
  const OmeMultiscales& multiscales() const noexcept;
  /// `.zarray` of dataset i (in multiscales order); throws Error(out_of_range).
  const ZarrArrayMeta& array(std::size_t dataset) const;
  /// The dataset that serves hierarchy level l, or -1 when the level is computed.
  int dataset_of_level(std::uint32_t level) const noexcept;
  /// Decoded-chunk cache statistics (hits, misses, evictions).
  HostBrickCacheStats chunk_cache_stats() const;

  /// The extent of the `t` axis (1 without one), capped at 2^32 - 1.
  std::uint32_t timepoints() const override;
  std::uint32_t timepoint() const override;
  /// The image at timepoint t: a new OmeZarrSource over the same store with this source's
  /// volume description (value ranges included) and options; its chunk cache has the same
  /// budget. Throws invalid_parameter("timepoint") for t >= timepoints() and what reading the
  /// new timepoint's level 0 throws when its metadata is scanned eagerly.
  std::shared_ptr<const BrickSource> open_timepoint(std::uint32_t t) const override;

 private:
  std::shared_ptr<const detail::ZarrImage> image_;
  std::vector<int> level_dataset_;
  PyramidSourceOptions options_;
};

/// Opens the image group at the root of `store`. Throws Error(bad_magic) when the store has
/// neither a `multiscales` `.zattrs` nor a root `.zarray`, what the metadata parsers throw
/// (naming the file and key), Error(corrupt) naming the file when datasets disagree with the
/// axes or each other, Error(unsupported) for more than 256 channels or a chunk grid beyond
/// 131072 chunks per axis, invalid_parameter("timepoint") past the last timepoint, and chunk
/// decode errors (naming the chunk's location) during the eager level-0 passes or later reads.
std::unique_ptr<OmeZarrSource> open_ome_zarr(std::shared_ptr<const ByteStore> store,
                                             const BrickLayout& layout = {},
                                             const OmeZarrOptions& options = {});

/// open_ome_zarr over a local directory store.
std::unique_ptr<OmeZarrSource> open_ome_zarr(const std::string& directory,
                                             const BrickLayout& layout = {},
                                             const OmeZarrOptions& options = {});

}  // namespace resoct
