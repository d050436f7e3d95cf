#pragma once
/// \file
/// Slice planes and the volume lens of a Scene (docs/scene.md "Slices and lens"; paper 001's
/// roaming through seismic volumes with slices and volume-rendering lenses). Plain value types;
/// the JSON reading and validation live with the scene (scene.hpp).

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace resoct {

/// Most slice planes one scene may hold (the kernel's per-frame record has room for these).
inline constexpr std::uint32_t kMaxSlices = 4;

/// An arbitrarily oriented plane through the volume that shows some of the scene's channels.
/// Rendered through the same page table, LOD choice and requests as the volume.
struct SlicePlane {
  glm::dvec3 point{0.5};             ///< a point on the plane, box coordinates
  glm::dvec3 normal{0.0, 0.0, 1.0};  ///< non-zero; its length does not matter
  /// Dataset channels shown; each must be one of the scene's channels.
  std::vector<std::uint32_t> channels;
  /// Window/level in the channel's normalized value range: when set, a channel shows the grey
  /// value clamp((v - level) / window + 1/2, 0, 1), opaque; otherwise its transfer function's
  /// colour and alpha (not opacity-corrected: a plane has no thickness).
  std::optional<double> window;  ///< > 0
  std::optional<double> level;   ///< finite; set together with window
  friend bool operator==(const SlicePlane&, const SlicePlane&) = default;
};

/// What a channel shows outside the lens.
struct LensOutside {
  std::uint32_t channel = 0;  ///< one of the scene's channels
  bool hide = true;           ///< nothing outside; else the level range below
  std::uint32_t finest_level = 0;
  std::uint32_t coarsest_level = 15;
  friend bool operator==(const LensOutside&, const LensOutside&) = default;
};

/// An oriented box inside which the scene's channels are volume-rendered as usual. Outside it a
/// channel shows nothing (the default) or renders within another, typically coarser, level range.
/// Only what is sampled is requested, so a lens in a huge volume pages in its neighbourhood.
struct Lens {
  glm::dvec3 center{0.5};  ///< box coordinates
  glm::dvec3 size{0.25};   ///< full edge lengths along the axes, box units, each > 0
  /// Columns are the box's unit axes (orthonormal).
  glm::dmat3 axes{1.0};
  /// Per channel; channels not listed are hidden outside.
  std::vector<LensOutside> outside;
  friend bool operator==(const Lens&, const Lens&) = default;
};

}  // namespace resoct
