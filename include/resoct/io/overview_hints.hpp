#pragma once
/// \file
/// Display hints a source's metadata carries, for overview_scene(volume, viewport, hints): the
/// first view of a volume takes its channels' colours and windows from the data where it can.

#include <optional>
#include <string_view>

#include <glm/vec3.hpp>

#include "resoct/scene/overview_scene.hpp"
#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// The hints `source` offers, per dataset channel:
///  - an OME-Zarr image (OmeZarrSource) with `omero.channels`: each channel's `color` and
///    `window` (docs/formats.md);
///  - every channel the overview shows (the first kOverviewChannels) that has no window gets a
///    histogram of its values at the coarsest pyramid level (coarse_value_histogram: one brick
///    per channel, read here), so that overview_scene ramps from its 50th to its 99.5th
///    percentile. No reader's metadata carries a histogram.
/// Never throws for odd metadata: an unreadable colour is left out, a brick that cannot be read
/// leaves the histogram empty (the ramp over the value range). Thread-safety: a pure
/// function of the source.
OverviewHints overview_hints(const BrickSource& source);

/// "RRGGBB" or "#RRGGBB" (hex, either case) as RGB in [0, 1]; nothing otherwise.
std::optional<glm::dvec3> parse_hex_colour(std::string_view text) noexcept;

}  // namespace resoct
