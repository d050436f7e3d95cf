#pragma once
// Physical placement of the single-resolution formats (internal): from a file's voxel-to-world
// map (NIfTI sform / qform, NRRD space directions and origin) to the served axis order, spacing
// and VolumeDesc::origin, and the voxel reordering that goes with it. One rule for every format
// so that two files on one world grid are served on one voxel grid, whatever their storage
// order.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace resoct::detail {

/// A file's voxel grid in world space: the centre of voxel (i, j, k) lies at
/// centre0 + axes * (i, j, k) (axes' columns are the world steps of i, j and k).
struct VoxelGrid {
  glm::dmat3 axes{1.0};
  glm::dvec3 centre0{0.0};
};

/// Where each served axis comes from: served axis a walks stored axis from[a], backwards when
/// flip[a].
struct AxisOrder {
  std::array<int, 3> from{0, 1, 2};
  std::array<bool, 3> flip{};
  bool identity() const noexcept {
    return from == std::array<int, 3>{0, 1, 2} && flip == std::array<bool, 3>{};
  }
};

struct Placement {
  AxisOrder order;
  glm::dvec3 spacing{1.0};  ///< per served axis
  glm::dvec3 origin{0.0};   ///< low corner of served voxel 0
  /// The grid is rotated or sheared beyond a permutation with flips: the nearest axis-aligned
  /// placement is served and the residual rotation is dropped.
  bool oblique = false;
};

/// The axis-aligned placement nearest to `grid` for a stored volume of `extent` voxels: served
/// axis a is the stored axis whose world step is most along world axis a (largest components
/// first), flipped when that step points to -a, so that served +x, +y, +z follow world +x, +y,
/// +z. Spacing is the length of each step; origin the world position of the centre of the
/// stored voxel that becomes served voxel 0, minus half a spacing. A grid with a non-finite
/// entry or a zero step keeps the stored order (spacing: finite positive lengths, else 1; origin:
/// centre0 - spacing / 2 when finite, else 0).
Placement place_grid(const VoxelGrid& grid, glm::u64vec3 extent) noexcept;

/// The served extent of a stored volume of `extent` voxels.
glm::u64vec3 served_extent(const AxisOrder& order, glm::u64vec3 extent) noexcept;

/// Copies `channels` stored volumes of `extent` voxels (x fastest, one channel after another,
/// `voxel_bytes` each) from `in` into `out` in served order (same sizes).
void reorder_voxels(std::span<const std::byte> in, glm::u64vec3 extent, std::uint32_t channels,
                    std::size_t voxel_bytes, const AxisOrder& order, std::span<std::byte> out);

}  // namespace resoct::detail
