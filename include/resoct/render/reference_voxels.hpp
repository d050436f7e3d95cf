#pragma once
/// \file
/// Level 0 of a brick source, materialized for the dense reference renderer
/// (reference_renderer.hpp): what `resoct-render --report-accuracy` compares a frame against.

#include <cstdint>
#include <functional>
#include <span>

#include "resoct/render/reference_renderer.hpp"
#include "resoct/sources/brick_source.hpp"

namespace resoct::reference {

/// Reads every level-0 brick of `channels` (dataset channel indices) from `source` and returns
/// their raw voxel values as a VoxelFunction (float storage, x fastest). Reading another channel
/// through it throws Error(out_of_range). `progress(done, total)` is called after each brick when
/// given. Throws Error(invalid_argument) naming `parameter` when the channels need more than
/// `max_bytes` of memory (4 bytes per voxel and channel), or when a channel is not in the source;
/// the source's own errors pass through.
VoxelFunction level0_voxels(const BrickSource& source, std::span<const std::uint32_t> channels,
                            std::uint64_t max_bytes, const std::string& parameter,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace resoct::reference
