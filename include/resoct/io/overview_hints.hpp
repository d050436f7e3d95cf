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
///  - no other reader exposes display metadata or a value histogram today, so their hints are
///    empty and overview_scene falls back to ramps over the value ranges.
/// Never throws for odd metadata: an unreadable colour is left out. Thread-safety: a pure
/// function of the source.
OverviewHints overview_hints(const BrickSource& source);

/// "RRGGBB" or "#RRGGBB" (hex, either case) as RGB in [0, 1]; nothing otherwise.
std::optional<glm::dvec3> parse_hex_colour(std::string_view text) noexcept;

}  // namespace resoct
