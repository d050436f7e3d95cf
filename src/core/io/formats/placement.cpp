#include "io/formats/placement.hpp"

#include <cmath>
#include <cstring>

namespace resoct::detail {

namespace {

bool finite(const VoxelGrid& g) noexcept {
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      if (!std::isfinite(g.axes[c][r])) return false;
    }
  }
  return true;
}

}  // namespace

Placement place_grid(const VoxelGrid& grid, glm::u64vec3 extent) noexcept {
  Placement p;
  glm::dvec3 length(0.0);
  for (int c = 0; c < 3; ++c) length[c] = glm::length(grid.axes[c]);
  const bool usable = finite(grid) && length.x > 0.0 && length.y > 0.0 && length.z > 0.0 &&
                      std::isfinite(length.x + length.y + length.z);
  if (usable) {
    // Greedy by the largest remaining |component| (of unit steps, so that a long step does not
    // outvote a short one): a permutation with flips is found exactly, an oblique grid gets the
    // world axis each step is closest to.
    bool row_used[3] = {}, col_used[3] = {};
    for (int n = 0; n < 3; ++n) {
      int best_r = -1, best_c = -1;
      double best = -1.0;
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) {
          const double v = std::fabs(grid.axes[c][r]) / length[c];
          if (!row_used[r] && !col_used[c] && v > best) best = v, best_r = r, best_c = c;
        }
      }
      row_used[best_r] = col_used[best_c] = true;
      p.order.from[std::size_t(best_r)] = best_c;
      p.order.flip[std::size_t(best_r)] = grid.axes[best_c][best_r] < 0.0;
      p.spacing[best_r] = length[best_c];
      // Off-axis components above ~0.006 degrees: the step is not along its world axis.
      for (int r = 0; r < 3; ++r) {
        if (r != best_r && std::fabs(grid.axes[best_c][r]) > 1e-4 * length[best_c]) {
          p.oblique = true;
        }
      }
    }
  } else {
    for (int c = 0; c < 3; ++c) {
      p.spacing[c] = std::isfinite(length[c]) && length[c] > 0.0 ? length[c] : 1.0;
    }
  }
  glm::dvec3 first(0.0);  // stored index of the voxel that becomes served voxel 0
  for (int a = 0; a < 3; ++a) {
    const int s = p.order.from[std::size_t(a)];
    if (p.order.flip[std::size_t(a)]) first[s] = double(extent[s] - 1);
  }
  const glm::dvec3 centre = usable ? grid.centre0 + grid.axes * first : grid.centre0;
  for (int a = 0; a < 3; ++a) {
    const double o = centre[a] - 0.5 * p.spacing[a];
    p.origin[a] = std::isfinite(o) ? o : 0.0;
  }
  return p;
}

glm::u64vec3 served_extent(const AxisOrder& order, glm::u64vec3 extent) noexcept {
  return {extent[order.from[0]], extent[order.from[1]], extent[order.from[2]]};
}

void reorder_voxels(std::span<const std::byte> in, glm::u64vec3 extent, std::uint32_t channels,
                    std::size_t voxel_bytes, const AxisOrder& order, std::span<std::byte> out) {
  const glm::u64vec3 se = served_extent(order, extent);
  const std::int64_t stored_stride[3] = {1, std::int64_t(extent.x),
                                         std::int64_t(extent.x * extent.y)};
  // Stride and start (in stored voxels) of each served axis.
  std::int64_t stride[3], start = 0;
  for (int a = 0; a < 3; ++a) {
    const int s = order.from[std::size_t(a)];
    stride[a] = order.flip[std::size_t(a)] ? -stored_stride[s] : stored_stride[s];
    if (order.flip[std::size_t(a)]) start += std::int64_t(extent[s] - 1) * stored_stride[s];
  }
  const std::uint64_t per_channel = extent.x * extent.y * extent.z;
  std::byte* dst = out.data();
  for (std::uint32_t c = 0; c < channels; ++c) {
    const std::byte* base = in.data() + std::size_t(c * per_channel) * voxel_bytes;
    for (std::uint64_t z = 0; z < se.z; ++z) {
      for (std::uint64_t y = 0; y < se.y; ++y) {
        std::int64_t i = start + std::int64_t(z) * stride[2] + std::int64_t(y) * stride[1];
        for (std::uint64_t x = 0; x < se.x; ++x, i += stride[0], dst += voxel_bytes) {
          std::memcpy(dst, base + std::size_t(i) * voxel_bytes, voxel_bytes);
        }
      }
    }
  }
}

}  // namespace resoct::detail
