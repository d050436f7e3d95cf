// Exact leaf records from level-0 brick voxels: the scan behind ResidencyOctree's exact culling
// metadata, free of octree state so that the brick loader can run it on its threads.
#include "resoct/engine/leaf_scan.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

#include "resoct/base/error.hpp"
#include "resoct/engine/residency_octree.hpp"

namespace resoct {

namespace {

template <class T>
VoxelBoxScan scan_rows(std::span<const std::byte> voxels, const glm::i64vec3& padded_lo,
                       const glm::i64vec3& padded_dim, const Box3& box, const ValueRange& range) {
  constexpr bool is_float = std::is_floating_point_v<T>;
  const T none_lo = is_float ? std::numeric_limits<T>::infinity() : std::numeric_limits<T>::max();
  const T none_hi =
      is_float ? -std::numeric_limits<T>::infinity() : std::numeric_limits<T>::lowest();
  const std::int64_t n = box.hi.x - box.lo.x;
  VoxelBoxScan s;
  for (std::int64_t z = box.lo.z; z < box.hi.z; ++z) {
    for (std::int64_t y = box.lo.y; y < box.hi.y; ++y) {
      const std::byte* row =
          voxels.data() +
          std::size_t((y - padded_lo.y + padded_dim.y * (z - padded_lo.z)) * padded_dim.x +
                      box.lo.x - padded_lo.x) *
              sizeof(T);
      T lo = none_lo, hi = none_hi;
      for (std::int64_t x = 0; x < n; ++x) {
        T t;
        std::memcpy(&t, row + std::size_t(x) * sizeof(T), sizeof(T));
        // NaN compares false both ways and is skipped.
        lo = t < lo ? t : lo;
        hi = t > hi ? t : hi;
      }
      if (!(lo <= hi)) continue;  // only NaN
      s.min = std::min(s.min, double(lo));
      s.max = std::max(s.max, double(hi));
      const std::uint32_t a = occupancy_bit(double(lo), range);
      if (a == occupancy_bit(double(hi), range)) {
        s.occupancy |= a;
        continue;
      }
      for (std::int64_t x = 0; x < n; ++x) {
        T t;
        std::memcpy(&t, row + std::size_t(x) * sizeof(T), sizeof(T));
        s.occupancy |= occupancy_bit(double(t), range);  // 0 for NaN
      }
    }
  }
  return s;
}

void check_level0_brick(const BrickHierarchy& hierarchy, glm::uvec3 brick) {
  const glm::uvec3 n = hierarchy.level(0).bricks;
  if (brick.x >= n.x || brick.y >= n.y || brick.z >= n.z) {
    throw Error(ErrorCode::out_of_range, "brick (" + std::to_string(brick.x) + ", " +
                                             std::to_string(brick.y) + ", " +
                                             std::to_string(brick.z) + ") outside level 0");
  }
}

}  // namespace

VoxelBoxScan scan_voxel_box(std::span<const std::byte> voxels, VoxelType type,
                            const glm::i64vec3& padded_lo, const glm::i64vec3& padded_dim,
                            const Box3& box, const ValueRange& range) {
  switch (type) {
    case VoxelType::u8: return scan_rows<std::uint8_t>(voxels, padded_lo, padded_dim, box, range);
    case VoxelType::u16: return scan_rows<std::uint16_t>(voxels, padded_lo, padded_dim, box, range);
    case VoxelType::f32: break;
  }
  return scan_rows<float>(voxels, padded_lo, padded_dim, box, range);
}

void for_each_exact_leaf(const OctreeLayout& layout, const BrickHierarchy& hierarchy,
                         glm::uvec3 brick,
                         const std::function<void(std::uint64_t leaf, const Box3& support)>& f) {
  check_level0_brick(hierarchy, brick);
  // A leaf's metadata covers its sampling support (the leaf grown by one voxel, what a trilinear
  // sample inside it reads), which the padded level-0 brick holds for the leaves of its core
  // when the halo is at least one voxel.
  const Box3 box0 = hierarchy.level0_box(0, brick);
  const glm::i64vec3 halo(hierarchy.layout().halo);
  const Box3 padded0 = intersect(Box3{box0.lo - halo, box0.hi + halo},
                                 Box3{glm::i64vec3(0), glm::i64vec3(layout.extent0())});
  const std::uint32_t d = layout.leaf_depth();
  layout.for_each_node(d, layout.node_range(d, box0), [&](std::uint64_t leaf, glm::uvec3 c) {
    const Box3 nb = layout.node_box(d, c);
    if (nb.empty() || intersect(nb, box0) != nb) return;  // only leaves the core fully covers
    const Box3 support = layout.sampling_support(leaf);
    if (intersect(support, padded0) == support) f(leaf, support);
  });
}

std::vector<LeafScan> scan_leaves(const OctreeLayout& layout, const BrickHierarchy& hierarchy,
                                  const ValueRange& range, glm::uvec3 brick,
                                  std::span<const std::byte> voxels) {
  check_level0_brick(hierarchy, brick);
  const VoxelType type = hierarchy.volume().type;
  const std::uint64_t expected = hierarchy.layout().padded_voxels() * voxel_size(type);
  if (voxels.size() != expected) {
    throw invalid_parameter("voxels", "brick buffer has " + std::to_string(voxels.size()) +
                                          " bytes, expected " + std::to_string(expected));
  }
  const Box3 core = hierarchy.core_box(0, brick);
  const glm::i64vec3 padded_lo = core.lo - glm::i64vec3(hierarchy.layout().halo);
  const glm::i64vec3 padded_dim(hierarchy.layout().padded_size());
  std::vector<LeafScan> out;
  for_each_exact_leaf(layout, hierarchy, brick, [&](std::uint64_t leaf, const Box3& support) {
    const VoxelBoxScan s = scan_voxel_box(voxels, type, padded_lo, padded_dim, support, range);
    out.push_back(LeafScan{leaf, octree_pack_range(s.min, s.max, range), s.occupancy});
  });
  return out;
}

std::vector<LeafScan> scan_constant_leaves(const OctreeLayout& layout,
                                           const BrickHierarchy& hierarchy, const ValueRange& range,
                                           glm::uvec3 brick, const BrickMeta& meta) {
  check_level0_brick(hierarchy, brick);
  if (!meta.constant) throw invalid_parameter("meta", "the brick is not constant");
  // Every finite voxel of the padded brick has the one value (or there is none).
  const std::uint32_t mm = octree_pack_range(meta.min, meta.max, range);
  const std::uint32_t occupancy = meta.min <= meta.max ? occupancy_bit(meta.min, range) : 0u;
  std::vector<LeafScan> out;
  for_each_exact_leaf(layout, hierarchy, brick, [&](std::uint64_t leaf, const Box3&) {
    out.push_back(LeafScan{leaf, mm, occupancy});
  });
  return out;
}

}  // namespace resoct
