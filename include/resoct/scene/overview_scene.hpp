#pragma once
/// \file
/// A first view of any volume, so that a viewer (or a script) renders something sensible before
/// the user has chosen a camera and transfer functions.

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/scene/camera.hpp"
#include "resoct/scene/scene.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

/// Channels overview_scene() makes visible at most (microscopy viewers show a handful at once).
inline constexpr std::uint32_t kOverviewChannels = 4;

/// The whole volume in view: a perspective camera (40 degrees) looks at the centre of the box
/// along the (+x, +y, +z) diagonal, from where the box's bounding sphere fits the view, with +y
/// up. The first min(channels, kOverviewChannels) channels are visible, each with a ramp transfer
/// function in a colour of its own (transparent below 10 % of the channel's range, opacity 0.5 per
/// voxel at its top), in front of a black background. Throws Error(invalid_argument) naming
/// "volume" or "viewport" when either is invalid.
Scene overview_scene(const VolumeDesc& volume, const Viewport& viewport = {});

/// What a source knows about displaying one channel (OverviewHints): any field may be absent.
struct ChannelDisplayHint {
  /// Display colour, RGB each in [0, 1] (OME-Zarr: `omero.channels[c].color`).
  std::optional<glm::dvec3> colour;
  /// Display window in the file's units, as VolumeDesc::data_range (OME-Zarr:
  /// `omero.channels[c].window`): values below `lo` are transparent, the ramp tops out at `hi`.
  std::optional<ValueRange> window;
  /// Value counts in equal bins over the channel's range (VolumeDesc::range(c), stored units),
  /// bin i covering [lo + i w, lo + (i + 1) w): a distribution the source's metadata offers.
  /// Empty when unknown.
  std::vector<std::uint64_t> histogram;
  friend bool operator==(const ChannelDisplayHint&, const ChannelDisplayHint&) = default;
};

/// Per dataset channel (index = channel; missing entries mean no hint), from the source's
/// metadata (resoct::overview_hints in io/overview_hints.hpp reads them from a BrickSource).
struct OverviewHints {
  std::vector<ChannelDisplayHint> channels;
};

/// Percentile of the ramp's start and end taken from a histogram (no window given).
inline constexpr double kOverviewLowPercentile = 50.0;
inline constexpr double kOverviewHighPercentile = 99.5;

/// overview_scene(volume, viewport) with each visible channel's transfer function taken from the
/// data where `hints` has something for it, in this order:
///  - a window: transparent up to the window's start, a ramp to opacity 0.5 at its end (values
///    clamped to the channel's range; an empty window after clamping is ignored);
///  - else a histogram with counts: the same ramp from its kOverviewLowPercentile-th to its
///    kOverviewHighPercentile-th percentile (linear within a bin);
///  - else the ramp over the channel's range (transparent below 10 %).
/// A hinted colour replaces the channel's palette colour. The camera is the same. Throws as
/// overview_scene, and Error(invalid_argument) naming "hints" when a colour component is outside
/// [0, 1] or not finite.
Scene overview_scene(const VolumeDesc& volume, const Viewport& viewport,
                     const OverviewHints& hints);

/// The percentile `p` (0..100) of a histogram's values in normalized units [0, 1] (bin i covers
/// [i / n, (i + 1) / n); linear within a bin), or nothing when every count is 0.
std::optional<double> histogram_percentile(const std::vector<std::uint64_t>& histogram, double p);

}  // namespace resoct
