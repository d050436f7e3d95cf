#pragma once
/// \file
/// OME-NGFF image metadata: the `.zattrs` of an OME-Zarr 0.4 image group (zarr v2) or the
/// `attributes.ome` of an OME-Zarr 0.5 group `zarr.json` (zarr v3): the `multiscales` levels with
/// their coordinate transformations, the axes, and `omero` channel display metadata when
/// present. Both versions share one structure; 0.5 moves it under `attributes.ome` and its
/// version to `attributes.ome.version`.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// One resolution level of a multiscales image: the array at `path` (a store key relative to
/// the group) and its physical scale and translation per axis (in the order of
/// OmeMultiscales::axes; a global transformation of the multiscales object is folded in).
struct OmeDataset {
  std::string path;
  std::vector<double> scale;        ///< each a positive finite number
  std::vector<double> translation;  ///< zeros when the file gives none
};

/// `omero.channels[i]`: display hints; resoct uses `window` as the channel's value range.
struct OmeChannel {
  std::string label;
  std::string color;                 ///< hex RRGGBB as written, may be empty
  std::optional<ValueRange> window;  ///< [window.start, window.end] when start < end
};

struct OmeMultiscales {
  std::string version;  ///< "0.4" or "0.5"
  std::string name;
  /// Axis names in array order, each one of 't', 'c', 'z', 'y', 'x', in that relative order
  /// (NGFF: time, then channel, then space), each at most once, at least one spatial.
  std::vector<char> axes;
  std::vector<std::string> units;    ///< per axis, "" when not given
  std::vector<OmeDataset> datasets;  ///< finest first, at least one
  std::vector<OmeChannel> channels;  ///< from `omero`, empty when absent

  /// Position of axis `axis` in `axes`, or -1.
  int axis_index(char axis) const noexcept;
};

/// Parses the `.zattrs` JSON of an image group; the first entry of `multiscales` is used.
/// Throws Error(corrupt) naming `location` and the key (e.g. "multiscales[0].datasets[1].
/// coordinateTransformations") for malformed JSON, missing or mistyped keys, unknown or
/// misordered axes, a scale of the wrong length or a non-positive scale, a dataset path that
/// is not a safe store key; Error(unsupported_version) when `version` is not "0.4";
/// Error(bad_magic) when there is no `multiscales` key (not an OME-Zarr image).
/// Thread-safety: a pure function.
OmeMultiscales parse_ome_multiscales(std::string_view json, std::string_view location);

/// Parses the `zarr.json` of an OME-Zarr 0.5 image group (zarr_format 3, node_type "group",
/// `attributes.ome` with version "0.5"); keys in messages start with "attributes.ome.".
/// Throws Error(bad_magic) when it is not a group or has no `attributes.ome` /
/// `attributes.ome.multiscales`, Error(unsupported_version) for zarr_format != 3 or an
/// `attributes.ome.version` other than "0.5", and what parse_ome_multiscales throws for the
/// rest. Thread-safety: a pure function.
OmeMultiscales parse_ome_zarr_group(std::string_view json, std::string_view location);

}  // namespace resoct
