#include "resoct/render/traversal_depths.hpp"

#include <algorithm>

namespace resoct {

float node_shortest_side(const kernel::ResoctDepthInfo& D, const kernel::ResoctFrame& f) {
  return std::min(float(D.node_extent_x) / f.voxels_per_box_x,
                  std::min(float(D.node_extent_y) / f.voxels_per_box_y,
                           float(D.node_extent_z) / f.voxels_per_box_z));
}

std::uint32_t traversal_depth(std::span<const kernel::ResoctDepthInfo> depths, std::uint32_t start,
                              const kernel::ResoctFrame& f, float dt) {
  std::uint32_t depth = start;
  for (std::uint32_t d = start + 1; d < depths.size(); ++d) {
    if (node_shortest_side(depths[d], f) < dt) break;
    depth = d;
  }
  return depth;
}

std::uint32_t level_depth_cap(std::span<const kernel::ResoctDepthInfo> depths, std::uint32_t start,
                              const kernel::ResoctLevelInfo& L) {
  std::uint32_t depth = start;
  for (std::uint32_t d = start + 1; d < depths.size(); ++d) {
    const kernel::ResoctDepthInfo& D = depths[d];
    if ((D.node_extent_x >> L.factor_log2_x) < 2u || (D.node_extent_y >> L.factor_log2_y) < 2u ||
        (D.node_extent_z >> L.factor_log2_z) < 2u) {
      break;
    }
    depth = d;
  }
  return depth;
}

}  // namespace resoct
