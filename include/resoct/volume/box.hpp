#pragma once
/// \file
/// Half-open integer boxes of voxels, with signed coordinates so that halo regions may start
/// before the volume.

#include <algorithm>
#include <cstdint>
#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace resoct {

struct Box3 {
  glm::i64vec3 lo{0};  ///< first voxel, inclusive
  glm::i64vec3 hi{0};  ///< one past the last voxel

  bool empty() const noexcept { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
  glm::i64vec3 size() const noexcept { return glm::max(hi - lo, glm::i64vec3(0)); }
  std::int64_t volume() const noexcept {
    const glm::i64vec3 s = size();
    return s.x * s.y * s.z;
  }
  bool contains(const glm::i64vec3& p) const noexcept {
    return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x < hi.x && p.y < hi.y && p.z < hi.z;
  }
  friend bool operator==(const Box3&, const Box3&) = default;
};

inline Box3 intersect(const Box3& a, const Box3& b) noexcept {
  return Box3{glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)};
}

inline bool overlaps(const Box3& a, const Box3& b) noexcept {
  return !intersect(a, b).empty();
}

}  // namespace resoct
