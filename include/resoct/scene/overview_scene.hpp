#pragma once
/// \file
/// A first view of any volume, so that a viewer (or a script) renders something sensible before
/// the user has chosen a camera and transfer functions.

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

}  // namespace resoct
