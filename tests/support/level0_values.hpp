#pragma once
// Every level-0 voxel of one channel of a format reader's source, as doubles (x fastest), for
// comparing against the values a test wrote into a file.
#include <cstdint>
#include <vector>

#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// `source` must be a PyramidSource (every format reader returns one).
std::vector<double> level0_values(const BrickSource& source, std::uint32_t channel);

}  // namespace resoct
