#pragma once
/// \file
/// The Octreemizer's neighbourhood distance (Plate et al. 2002, "Paging from hard disk into main
/// memory"): how many bricks away a brick lies from the current wish list tree, the discard
/// priority's d. See docs/core-structures.md ("Octreemizer priority").

#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/volume/brick_key.hpp"
#include "resoct/volume/hierarchy.hpp"

namespace resoct {

/// The wish list tree of one frame and the neighbourhood distance to it. The tree is the wish
/// list (the bricks the frame sampled or requested) with every coarser ancestor of each, so that
/// a coarse brick the wished ones refine has distance 0 too. A brick's distance is the Chebyshev
/// distance, in bricks of its own level, to the nearest tree brick of the same channel and level:
/// 0 on the tree, 1 for its 26 neighbours, 2 for the 98 around those, and so on. Where the
/// channel has no tree brick at that level, the distance is kFar.
///
/// assign() is O(w log w) for w tree bricks (one k-d tree per channel and level); distance() is
/// an L-infinity nearest-neighbour query, O(log w) for a typical layout. Thread-safety: const
/// members may run concurrently.
class WishListDistance {
 public:
  /// Distance of a brick whose channel has no tree brick at its level: farther than any brick
  /// of a level can be from another (BrickKey axes have 17 bits).
  static constexpr std::uint32_t kFar = 1u << 17;

  /// An empty wish list over `h` (every distance kFar). `h` must outlive this object.
  explicit WishListDistance(const BrickHierarchy& h);

  /// Replaces the wish list. Keys outside the hierarchy throw Error(out_of_range) naming the key,
  /// and leave the previous wish list in place.
  void assign(std::span<const BrickKey> wish);

  /// The neighbourhood distance of `key` (any key the hierarchy contains); kFar outside it.
  std::uint32_t distance(BrickKey key) const;

  /// Bricks of the wish list tree (the wish list and its ancestors, each once).
  std::size_t tree_size() const noexcept { return tree_.size(); }

 private:
  // One k-d tree: points in median order (node i of range [b, e) is the point at (b + e) / 2,
  // split on axis depth % 3).
  using Points = std::vector<glm::ivec3>;
  static void build(Points& p, std::size_t b, std::size_t e, std::uint32_t depth);
  static void nearest(const Points& p, std::size_t b, std::size_t e, std::uint32_t depth,
                      glm::ivec3 q, std::uint32_t& best);

  const BrickHierarchy* h_;
  std::unordered_set<BrickKey> tree_;
  // Keyed by channel << 5 | level.
  std::unordered_map<std::uint32_t, Points> points_;
};

}  // namespace resoct
