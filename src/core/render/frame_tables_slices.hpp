#pragma once
// Internal: the slice and lens part of build_frame_tables (kernel/slice.glsl.h, lens.glsl.h).

#include "resoct/backend/backend.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct::detail {

/// Fills the frame's slice and lens fields and, with a lens, appends the outside bank to
/// out.slots. Expects out.slots to hold the scene's slot table (bank 0) and out.frame the camera.
/// Throws Error(invalid_argument) naming "scene.slices" / "scene.lens" when a position is too
/// far from the volume for the kernel's 32-bit cells.
void fill_slices_and_lens(const Scene& scene, const BrickHierarchy& hierarchy,
                          const ChannelMap& channels, FrameTables& out);

}  // namespace resoct::detail
