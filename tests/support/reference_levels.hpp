#pragma once
// Brute-force reference for coarser levels: the recursive definition of box filtering, written
// independently of resoct's downsampling code so that tests compare against a definition.

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/hierarchy.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct::test {

/// One level's voxels as doubles, x fastest.
struct RefLevel {
  glm::u64vec3 extent{0};
  std::vector<double> v;
  double at(std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
    return v[std::size_t((z * extent.y + y) * extent.x + x)];
  }
};

/// Level l voxel i = mean of the level l-1 voxels 2i, 2i+1 (those that exist) along each axis the
/// hierarchy halves between l-1 and l; NaN children ignored (all NaN gives NaN); integer types
/// round half up; f32 results are rounded to float.
std::vector<RefLevel> reference_levels(const BrickHierarchy& h, const std::vector<double>& level0,
                                       VoxelType t);

/// Clamp-to-edge: the level voxel a padded-brick coordinate reads.
inline std::int64_t clamp_index(std::int64_t v, std::uint64_t extent) {
  return v < 0 ? 0 : v >= std::int64_t(extent) ? std::int64_t(extent) - 1 : v;
}

/// Reads voxel i of a typed byte buffer as double.
double voxel_as_double(const std::byte* data, std::size_t i, VoxelType t);

}  // namespace resoct::test
