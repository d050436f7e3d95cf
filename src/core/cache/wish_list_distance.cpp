#include "resoct/cache/wish_list_distance.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

std::uint32_t table_of(BrickKey k) {
  return (k.channel() << 5) | k.level();
}

std::uint32_t chebyshev(glm::ivec3 a, glm::ivec3 b) {
  return std::uint32_t(std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)}));
}

}  // namespace

WishListDistance::WishListDistance(const BrickHierarchy& h) : h_(&h) {}

void WishListDistance::assign(std::span<const BrickKey> wish) {
  for (const BrickKey k : wish) {
    if (!h_->contains(BrickKey(k.level(), 0, k.brick())) || k.channel() >= h_->volume().channels) {
      throw Error(ErrorCode::out_of_range,
                  "wish list: brick key (level " + std::to_string(k.level()) + ", channel " +
                      std::to_string(k.channel()) + ") outside the hierarchy");
    }
  }
  tree_.clear();
  points_.clear();
  const std::uint32_t top = h_->level_count() - 1u;
  for (const BrickKey wished : wish) {
    BrickKey k = wished;
    // Up the ancestors until one is already in the tree (then so are all of its ancestors).
    while (tree_.insert(k).second) {
      points_[table_of(k)].push_back(glm::ivec3(k.brick()));
      const std::uint32_t l = k.level();
      if (l == top) break;
      // A coarser level halves an axis or keeps it: the parent brick is the child's coordinate
      // shifted by the factor difference (brick boxes nest, hierarchy.hpp).
      const glm::uvec3 shift = h_->level(l + 1u).factor_log2 - h_->level(l).factor_log2;
      k = BrickKey(l + 1u, k.channel(), k.brick() >> shift);
    }
  }
  for (auto& [table, p] : points_) build(p, 0, p.size(), 0);
}

void WishListDistance::build(Points& p, std::size_t b, std::size_t e, std::uint32_t depth) {
  if (e - b <= 1) return;
  const std::size_t m = b + (e - b) / 2;
  const int axis = int(depth % 3u);
  std::nth_element(p.begin() + std::ptrdiff_t(b), p.begin() + std::ptrdiff_t(m),
                   p.begin() + std::ptrdiff_t(e),
                   [axis](glm::ivec3 a, glm::ivec3 c) { return a[axis] < c[axis]; });
  build(p, b, m, depth + 1u);
  build(p, m + 1, e, depth + 1u);
}

void WishListDistance::nearest(const Points& p, std::size_t b, std::size_t e, std::uint32_t depth,
                               glm::ivec3 q, std::uint32_t& best) {
  if (b >= e || best == 0) return;
  const std::size_t m = b + (e - b) / 2;
  best = std::min(best, chebyshev(q, p[m]));
  const int axis = int(depth % 3u);
  const int diff = q[axis] - p[m][axis];
  // The near side first; the far side only when the splitting plane is closer than the best
  // (in L-infinity a point beyond the plane is at least |diff| away).
  if (diff < 0) {
    nearest(p, b, m, depth + 1u, q, best);
    if (std::uint32_t(-diff) < best) nearest(p, m + 1, e, depth + 1u, q, best);
  } else {
    nearest(p, m + 1, e, depth + 1u, q, best);
    if (std::uint32_t(diff) < best) nearest(p, b, m, depth + 1u, q, best);
  }
}

std::uint32_t WishListDistance::distance(BrickKey key) const {
  if (tree_.contains(key)) return 0;
  const auto it = points_.find(table_of(key));
  if (it == points_.end()) return kFar;
  std::uint32_t best = kFar;
  nearest(it->second, 0, it->second.size(), 0, glm::ivec3(key.brick()), best);
  return best;
}

}  // namespace resoct
