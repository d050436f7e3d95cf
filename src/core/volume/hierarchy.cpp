#include "resoct/volume/hierarchy.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

void BrickLayout::validate() const {
  for (int i = 0; i < 3; ++i) {
    if (brick_size[i] < 4 || brick_size[i] > 1024) {
      throw invalid_parameter(
          "brick_size", "each axis must be 4..1024 voxels, got " + std::to_string(brick_size[i]));
    }
  }
  if (halo > 4) throw invalid_parameter("halo", "must be 0..4, got " + std::to_string(halo));
}

namespace {
std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) {
  return a / b + (a % b != 0);
}

// Floor division for possibly negative coordinates (halo boxes start before the volume).
std::int64_t floor_shift(std::int64_t v, std::uint32_t s) {
  const std::int64_t d = std::int64_t(1) << s;
  return v >= 0 ? v / d : -((-v + d - 1) / d);
}
}  // namespace

BrickHierarchy::BrickHierarchy(VolumeDesc volume, BrickLayout layout)
    : volume_(std::move(volume)), layout_(layout) {
  volume_.validate();
  layout_.validate();
  const glm::u64vec3 b(layout_.brick_size);

  LevelInfo lvl;
  lvl.extent = volume_.extent;
  for (;;) {
    for (int i = 0; i < 3; ++i) {
      const std::uint64_t n = ceil_div(lvl.extent[i], b[i]);
      if (n > std::uint64_t(BrickKey::kMaxAxis) + 1u) {
        throw Error(ErrorCode::invalid_argument,
                    "volume extent " + std::to_string(volume_.extent[i]) + " along axis " +
                        std::to_string(i) + " needs " + std::to_string(n) +
                        " bricks at level 0; at most " + std::to_string(BrickKey::kMaxAxis + 1u) +
                        " fit a brick key (parameter 'brick_size': use larger bricks)");
      }
      lvl.bricks[i] = std::uint32_t(n);
    }
    lvl.brick_count = std::uint64_t(lvl.bricks.x) * lvl.bricks.y * lvl.bricks.z;
    lvl.first_brick = bricks_per_channel_;
    bricks_per_channel_ += lvl.brick_count;
    levels_.push_back(lvl);
    if (lvl.brick_count == 1) break;
    if (levels_.size() > BrickKey::kMaxLevel) {
      throw Error(ErrorCode::invalid_argument, "volume needs more than " +
                                                   std::to_string(BrickKey::kMaxLevel + 1u) +
                                                   " resolution levels");
    }
    // Extent in bricks decides which axes halve: an axis that is much smaller than the largest
    // one (anisotropic data such as 1024x1024x40) stays whole until the others catch up.
    const glm::dvec3 nb = glm::dvec3(lvl.extent) / glm::dvec3(b);
    const double largest = std::max({nb.x, nb.y, nb.z});
    LevelInfo next = lvl;
    for (int i = 0; i < 3; ++i) {
      if (lvl.bricks[i] > 1 && 2.0 * nb[i] > largest) {
        next.extent[i] = ceil_div(lvl.extent[i], 2);
        next.factor_log2[i] += 1;
      }
    }
    lvl = next;
  }
}

glm::dvec3 BrickHierarchy::level_voxel_position(std::uint32_t l, const glm::dvec3& p) const {
  const LevelInfo& li = level(l);
  glm::dvec3 x;
  for (int i = 0; i < 3; ++i) {
    x[i] = std::ldexp(p[i] * double(volume_.extent[i]), -int(li.factor_log2[i]));
  }
  return x;
}

glm::uvec3 BrickHierarchy::brick_at(std::uint32_t l, const glm::dvec3& p) const {
  const LevelInfo& li = level(l);
  const glm::dvec3 x = level_voxel_position(l, p);
  glm::uvec3 out;
  for (int i = 0; i < 3; ++i) {
    // floor(floor(x) / b): the voxel first, then its brick. Computing floor(p * bricks) instead
    // is wrong when the extent is not a multiple of the brick size.
    const double v = std::floor(x[i]);
    const double bi = v <= 0.0 ? 0.0 : std::floor(v / double(layout_.brick_size[i]));
    out[i] = std::uint32_t(std::min(bi, double(li.bricks[i] - 1)));
  }
  return out;
}

Box3 BrickHierarchy::core_box(std::uint32_t l, const glm::uvec3& brick) const {
  const LevelInfo& li = level(l);
  const glm::i64vec3 b(layout_.brick_size);
  Box3 box;
  box.lo = glm::i64vec3(brick) * b;
  box.hi = glm::min(box.lo + b, glm::i64vec3(li.extent));
  return box;
}

Box3 BrickHierarchy::padded_box(std::uint32_t /*level*/, const glm::uvec3& brick) const {
  const glm::i64vec3 b(layout_.brick_size);
  const glm::i64vec3 h(layout_.halo);
  const glm::i64vec3 lo = glm::i64vec3(brick) * b;
  return Box3{lo - h, lo + b + h};
}

Box3 BrickHierarchy::level0_box(std::uint32_t l, const glm::uvec3& brick) const {
  const LevelInfo& li = level(l);
  const Box3 c = core_box(l, brick);
  Box3 out;
  for (int i = 0; i < 3; ++i) {
    out.lo[i] = c.lo[i] << li.factor_log2[i];
    out.hi[i] = std::min(c.hi[i] << li.factor_log2[i], std::int64_t(volume_.extent[i]));
  }
  return out;
}

Box3 BrickHierarchy::level_box_from_level0(std::uint32_t l, const Box3& level0) const {
  const LevelInfo& li = level(l);
  Box3 out;
  for (int i = 0; i < 3; ++i) {
    const std::uint32_t f = li.factor_log2[i];
    out.lo[i] = floor_shift(level0.lo[i], f);
    out.hi[i] = -floor_shift(-level0.hi[i], f);  // ceiling
  }
  return out;
}

std::uint64_t BrickHierarchy::linear_index(std::uint32_t l, const glm::uvec3& brick) const {
  const LevelInfo& li = level(l);
  return li.first_brick + brick.x +
         std::uint64_t(li.bricks.x) * (brick.y + std::uint64_t(li.bricks.y) * brick.z);
}

BrickKey BrickHierarchy::key_from_linear(std::uint32_t channel, std::uint64_t index) const {
  if (index >= bricks_per_channel_) {
    throw Error(ErrorCode::out_of_range, "brick index " + std::to_string(index) + " past the " +
                                             std::to_string(bricks_per_channel_) +
                                             " bricks of a channel");
  }
  auto it =
      std::upper_bound(levels_.begin(), levels_.end(), index,
                       [](std::uint64_t i, const LevelInfo& li) { return i < li.first_brick; });
  const std::uint32_t l = std::uint32_t(it - levels_.begin()) - 1u;
  const LevelInfo& li = levels_[l];
  std::uint64_t r = index - li.first_brick;
  glm::uvec3 b;
  b.x = std::uint32_t(r % li.bricks.x);
  r /= li.bricks.x;
  b.y = std::uint32_t(r % li.bricks.y);
  b.z = std::uint32_t(r / li.bricks.y);
  return BrickKey(l, channel, b);
}

bool BrickHierarchy::contains(BrickKey key) const noexcept {
  if (key.level() >= levels_.size() || key.channel() >= volume_.channels) return false;
  const LevelInfo& li = levels_[key.level()];
  const glm::uvec3 b = key.brick();
  return b.x < li.bricks.x && b.y < li.bricks.y && b.z < li.bricks.z;
}

}  // namespace resoct
