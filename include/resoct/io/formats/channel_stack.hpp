#pragma once
/// \file
/// Several sources on one grid served as the channels of one dataset, e.g. an MRI volume plus
/// atlas label volumes registered to it.

#include <memory>
#include <string>
#include <vector>

#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// Channels of `sources[0]` come first, then those of `sources[1]`, and so on; ranges follow
/// the sources; spacing is that of the first. Bricks, brick metadata and region metadata are
/// forwarded to the source that owns the channel. Throws Error(invalid_argument) naming
/// "sources" when the list is empty or a source differs from the first in extent, voxel type
/// or brick layout, or the channels exceed kMaxChannels. Thread-safety: as BrickSource.
std::unique_ptr<BrickSource> stack_channels(std::vector<std::shared_ptr<const BrickSource>> sources,
                                            std::string name);

}  // namespace resoct
