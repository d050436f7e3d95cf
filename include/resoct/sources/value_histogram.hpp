#pragma once
/// \file
/// A channel's value distribution estimated from the source's coarsest pyramid level, for display
/// defaults (overview_hints' percentile windows) when the metadata has none.

#include <cstdint>
#include <vector>

#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// Counts of the core voxels of `channel` at the coarsest level in `bins` equal bins over
/// VolumeDesc::range(channel) (stored units; bin i covers [lo + i w, lo + (i + 1) w), values
/// outside the range counted in the first or last bin, NaN not at all), the layout
/// ChannelDisplayHint::histogram has. The coarsest level is one brick (BrickHierarchy builds
/// levels until one brick covers the volume), so this reads one brick: bounded cost whatever the
/// volume's size. Its voxels are averages of level-0 voxels, so the distribution is narrower than
/// level 0's (bright sparse structures pull the top percentiles less). Throws Error naming
/// "channel" or "bins" (1..2^20) when out of range, or as read_brick does.
std::vector<std::uint64_t> coarse_value_histogram(const BrickSource& source, std::uint32_t channel,
                                                  std::uint32_t bins);

}  // namespace resoct
