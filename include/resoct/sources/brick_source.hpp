#pragma once
/// \file
/// The interface every supplier of bricks implements: in-memory volumes, procedural volumes,
/// resoct's brick store and (later) OME-Zarr, NIfTI, NRRD, TIFF and HTTP.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include "resoct/volume/box.hpp"
#include "resoct/volume/brick_key.hpp"
#include "resoct/volume/hierarchy.hpp"

namespace resoct {

/// Summary of one brick's voxels, core and halo together (sampling near the border reads the
/// halo, so a brick is only homogeneous when its halo is too). NaN voxels are ignored; a brick of
/// only NaN has min = +inf, max = -inf and constant = true.
struct BrickMeta {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  bool constant = true;  ///< every non-NaN voxel equals min (== max)

  /// Constant zero: transparent under every transfer function, needs no cache slot.
  bool all_zero() const noexcept { return constant && min == 0.0 && max == 0.0; }
  friend bool operator==(const BrickMeta&, const BrickMeta&) = default;
};

/// Conservative summary of the *level-0* voxels of one channel inside a region: the true minimum
/// is >= min, the true maximum <= max, and every occupied value bin has its bit set in
/// `occupancy` (bins over the channel's ValueRange, see occupancy_bit()). A region holding only
/// NaN reports min = +inf, max = -inf, occupancy = 0.
struct RegionMeta {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  std::uint32_t occupancy = 0;

  /// Widens this summary to cover another one.
  void merge(const RegionMeta& o) noexcept {
    min = o.min < min ? o.min : min;
    max = o.max > max ? o.max : max;
    occupancy |= o.occupancy;
  }
  friend bool operator==(const RegionMeta&, const RegionMeta&) = default;
};

/// A supplier of bricks. All member functions are thread-safe: the loader calls them from many
/// threads at once.
class BrickSource {
 public:
  virtual ~BrickSource() = default;

  /// Hierarchy (volume description and brick layout) that keys refer to.
  virtual const BrickHierarchy& hierarchy() const = 0;
  const VolumeDesc& volume() const { return hierarchy().volume(); }

  /// Writes the brick with its halo into `out`: padded_size() voxels of volume().type, x fastest,
  /// then y, then z; halo and the part of a border brick beyond the level clamp to the nearest
  /// voxel of the level. `out.size()` must equal padded_voxels() * voxel_size(type).
  /// Throws Error when the key is not in the hierarchy or the underlying data is bad.
  virtual void read_brick(BrickKey key, std::span<std::byte> out) const = 0;

  /// Metadata of one brick. The default reads the brick and scans it; sources that store or
  /// can derive it cheaply override this.
  virtual BrickMeta brick_meta(BrickKey key) const;

  /// The down-sampling error of brick `key` in [0, 1] of the channel's value range, as
  /// measure_brick_error() (sources/brick_error.hpp) defines it, or a bound above it; `padded`
  /// holds the brick's voxels as read_brick() writes them. Error-bounded level of detail chooses
  /// levels by it (docs/rendering.md "Error-bounded LOD"). The default measures (reading the
  /// level-0 bricks under the brick); sources that store the errors (brick stores written with
  /// them) or cache them (PyramidSource) override it. Throws what read_brick throws, and
  /// Error(invalid_argument) naming "padded" for a wrongly sized buffer.
  virtual double brick_error(BrickKey key, std::span<const std::byte> padded) const;

  /// Conservative metadata of the level-0 voxels of `channel` inside `level0_region` (clamped
  /// to the volume). Culling relies on this, never on a coarse brick's averaged voxels alone.
  virtual RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const = 0;

  /// Human-readable name for messages: a path, a URL or "procedural:tubes:256x256x256".
  virtual std::string name() const = 0;

  // --- Time series (docs/renderer.md "Time series") --------------------------------------------
  // A source reads one timepoint of a series; every member above answers for that timepoint.
  // The other timepoints are separate sources (open_timepoint) with the same hierarchy, so that
  // everything derived from the data -- brick metadata, region metadata, computed levels and
  // their caches -- is per timepoint by construction and can never leak into another one.

  /// Timepoints of the series this source belongs to; 1 for data without a time axis.
  virtual std::uint32_t timepoints() const { return 1; }
  /// The timepoint this source reads, < timepoints().
  virtual std::uint32_t timepoint() const { return 0; }
  /// A source reading timepoint `t` (< timepoints(), != timepoint()) of the same series, with an
  /// identical hierarchy (value ranges included, so that a transfer function maps every
  /// timepoint alike). Called rarely (on a timepoint switch or prefetch of the next one); use
  /// source_at_timepoint(), which also handles t == timepoint(). The default throws
  /// Error(invalid_argument) naming "timepoint": a single-timepoint source has no other.
  virtual std::shared_ptr<const BrickSource> open_timepoint(std::uint32_t t) const;

 protected:
  /// Throws Error(out_of_range) naming this source when `key` is not in the hierarchy, and
  /// Error(invalid_argument) when `out` has the wrong size.
  void check_brick_request(BrickKey key, std::span<const std::byte> out) const;
};

/// `source` itself when t == source->timepoint(), else source->open_timepoint(t) after checking
/// that its hierarchy equals the series' one. Throws Error(invalid_argument) naming "timepoint"
/// when t >= timepoints(), Error(corrupt) naming the source when the opened timepoint's hierarchy
/// differs, and what open_timepoint throws.
std::shared_ptr<const BrickSource> source_at_timepoint(std::shared_ptr<const BrickSource> source,
                                                       std::uint32_t t);

/// Scans a padded brick buffer of type `t` for its metadata (NaN ignored).
BrickMeta scan_brick(std::span<const std::byte> voxels, VoxelType t);

}  // namespace resoct
