#pragma once
// A brick source for tests, defined by a function of (channel, level-0 voxel). Everything is
// computed by brute force from that definition, so it can serve as the reference for sources
// that store or derive bricks: coarse levels average the level-0 voxels of their footprint
// (NaN excluded), halos clamp to the level's edge, region_meta scans level-0 voxels.
// Only for tiny volumes: every level is materialized at construction.

#include <functional>
#include <string>
#include <vector>

#include "resoct/sources/brick_source.hpp"

namespace resoct::test {

class FunctionSource : public BrickSource {
 public:
  /// value(channel, level-0 voxel) in voxel units; integer types round to nearest and clamp to
  /// the type's range, f32 converts (NaN and Inf allowed).
  using ValueFn = std::function<double(std::uint32_t channel, const glm::u64vec3& voxel)>;

  FunctionSource(VolumeDesc volume, BrickLayout layout, ValueFn value,
                 std::string name = "function-source");

  const BrickHierarchy& hierarchy() const override { return hierarchy_; }
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override;
  std::string name() const override { return name_; }

  /// The voxel of a level (already converted to the voxel type), clamped to the level's edge.
  double voxel(std::uint32_t level, std::uint32_t channel, glm::i64vec3 p) const;

 private:
  BrickHierarchy hierarchy_;
  std::string name_;
  // levels_[l][c]: the level's voxels, x fastest, as exactly representable doubles.
  std::vector<std::vector<std::vector<double>>> levels_;
};

}  // namespace resoct::test
