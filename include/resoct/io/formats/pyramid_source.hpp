#pragma once
/// \file
/// Multiresolution on demand for inputs that store one resolution (NIfTI, NRRD, TIFF) or only
/// some levels (an OME-Zarr multiscales image with fewer levels than resoct's hierarchy).
///
/// A level the input stores is read through its reader; any other level l is computed brick by
/// brick from level l - 1 with downsample_region() (the project's one downsampling rule, along
/// exactly the axes BrickHierarchy halves) and the computed brick cores are kept in an LRU cache
/// with a byte budget, so a coarse level costs one pass over the finer one while it fits.
/// Region metadata: a level 0 of at most `eager_scan_voxels` voxels (all channels) is scanned at
/// construction into a MetadataPyramid; a larger one is summarized lazily, block by block on
/// first need, so opening costs O(metadata) whatever size the input declares (docs/formats.md).

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "resoct/sources/brick_source.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/cache/host_brick_cache.hpp"
#include "resoct/sources/metadata_pyramid.hpp"

namespace resoct {

namespace detail {
class LazyMetadata;     // on-demand block summaries (src/core/io/formats/lazy_metadata.hpp)
class BrickErrorCache;  // measured brick errors (src/core/io/formats/brick_error_cache.hpp)
}  // namespace detail

/// Fills `out` (dense, x fastest) with the voxels of `box` of one channel of one level; the box
/// lies inside the level. Must be callable from many threads at once.
using LevelBoxReader =
    std::function<void(std::uint32_t channel, const Box3& box, std::span<std::byte> out)>;

struct PyramidSourceOptions {
  /// Byte budget of computed coarse brick cores (LRU); 0 recomputes every time.
  std::uint64_t cache_bytes = std::uint64_t(256) << 20;
  /// Edge of a level-0 metadata block (power of two, 4..1024).
  std::uint32_t metadata_block = 16;
  /// Replace every channel's value range by the finite min/max of its level-0 data (an extra
  /// pass; [lo, lo + 1] for a constant channel, [0, 1] for one without finite voxels). With lazy
  /// metadata the pass reads the coarsest stored level instead when that one is within
  /// eager_scan_voxels, else the ranges stay default_range(type).
  bool ranges_from_data = false;
  /// Level-0 voxels (times channels) up to which construction scans level 0 eagerly; above it
  /// region metadata is computed lazily. 0 forces lazy metadata.
  std::uint64_t eager_scan_voxels = std::uint64_t(64) << 20;
  /// Lazy metadata: the most unknown metadata blocks one region_meta call reads (as one box);
  /// a query needing more answers the conservative "unknown" summary instead.
  std::uint32_t lazy_query_blocks = 64;
  /// Lazy metadata: cached block summaries (about 48 bytes each); a full cache shard is dropped.
  std::uint64_t lazy_cache_entries = std::uint64_t(1) << 20;
  /// Measured down-sampling errors kept (brick_error; about 64 bytes each); a full cache shard
  /// is dropped.
  std::uint64_t error_cache_entries = std::uint64_t(1) << 20;
  /// Threads of the level-0 passes; 0 = hardware concurrency.
  std::uint32_t threads = 0;
  /// A series whose other timepoints are other sources (a 4-D NIfTI re-read at another
  /// timepoint): how many there are, which one this source reads, and how to open timepoint t
  /// given this source (whose value ranges the other timepoints must keep, so that one transfer
  /// function maps the whole series alike: BrickSource::open_timepoint). Empty: one timepoint.
  std::uint32_t timepoints = 1;
  std::uint32_t timepoint = 0;
  std::function<std::shared_ptr<const BrickSource>(std::uint32_t t, const BrickSource& self)>
      open_timepoint;
};

/// Thread-safety: immutable after construction apart from the internal cache; every member may
/// be called from any number of threads at once.
class PyramidSource : public BrickSource {
 public:
  /// `levels[l]` reads hierarchy level l when the input stores it; empty entries and levels
  /// beyond the vector are built on demand. levels[0] must be set. Runs the level-0 passes
  /// when level 0 is within options.eager_scan_voxels.
  /// Throws Error(invalid_argument) for an invalid description, layout, options or a missing
  /// level-0 reader, and whatever the readers throw.
  PyramidSource(VolumeDesc desc, BrickLayout layout, std::vector<LevelBoxReader> levels,
                std::string name, PyramidSourceOptions options = {});
  ~PyramidSource() override;

  const BrickHierarchy& hierarchy() const override { return hierarchy_; }
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override;
  /// Measured on first need (measure_brick_error) and cached per source, so a brick loaded
  /// again after the host cache evicted it is not measured again.
  double brick_error(BrickKey key, std::span<const std::byte> padded) const override;
  std::string name() const override { return name_; }
  std::uint32_t timepoints() const override { return timepoints_; }
  std::uint32_t timepoint() const override { return timepoint_; }
  std::shared_ptr<const BrickSource> open_timepoint(std::uint32_t t) const override;

  /// The voxels of `box` (inside level `level`) of one channel, dense, x fastest.
  /// Throws Error(invalid_argument) for a bad level, channel, box or buffer size.
  void read_level_box(std::uint32_t level, std::uint32_t channel, const Box3& box,
                      std::span<std::byte> out) const;
  /// True when level `level` is read from the input rather than computed.
  bool stored_level(std::uint32_t level) const noexcept;
  /// The eager metadata pyramid (empty when lazy_metadata()).
  const MetadataPyramid& metadata() const noexcept { return pyramid_; }
  /// True when region metadata is computed on demand rather than scanned at construction.
  bool lazy_metadata() const noexcept { return lazy_ != nullptr; }
  /// Lazy metadata blocks computed so far (0 when eager).
  std::uint64_t lazy_blocks_computed() const noexcept;
  /// Brick errors measured so far (each miss of the error cache).
  std::uint64_t brick_errors_measured() const noexcept;
  HostBrickCacheStats cache_stats() const { return cache_->stats(); }

 private:
  std::shared_ptr<const HostBrick> computed_core(std::uint32_t level, std::uint32_t channel,
                                                 const glm::uvec3& brick) const;

  BrickHierarchy hierarchy_;
  std::vector<LevelBoxReader> levels_;
  std::string name_;
  MetadataPyramid pyramid_;
  std::unique_ptr<detail::LazyMetadata> lazy_;
  std::unique_ptr<HostBrickCache> cache_;
  std::unique_ptr<detail::BrickErrorCache> errors_;
  std::uint32_t timepoints_ = 1;
  std::uint32_t timepoint_ = 0;
  std::function<std::shared_ptr<const BrickSource>(std::uint32_t, const BrickSource&)>
      open_timepoint_;
};

/// A PyramidSource over voxels held in memory (level 0 only; coarser levels on demand).
std::unique_ptr<PyramidSource> make_dense_pyramid_source(DenseVolume volume, BrickLayout layout,
                                                         std::string name,
                                                         PyramidSourceOptions options = {});

/// The value range rule of ranges_from_data over one channel's voxels (exposed for tests).
ValueRange data_value_range(double finite_min, double finite_max) noexcept;

}  // namespace resoct
