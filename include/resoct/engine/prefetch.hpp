#pragma once
/// \file
/// Prefetching ahead of camera motion (paper 001, "predictive paging"): the camera's next poses
/// are extrapolated linearly from its last two, and the bricks such a view would sample are
/// enumerated conservatively (frustum x level of detail against the brick hierarchy), so that
/// the loader can read them into the host cache before the renderer asks for them.
/// See docs/renderer.md, "Prefetching".

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "resoct/volume/brick_key.hpp"
#include "resoct/scene/camera.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct {

/// Keeps the last two camera poses and extrapolates them. Thread-safety: none.
class CameraPredictor {
 public:
  /// Records the camera of a new frame.
  void observe(const Camera& camera);
  /// The poses 1..steps frames ahead: eye and target move on by their last per-frame
  /// displacement (k times for the k-th pose); up, field of view and projection are kept. Empty
  /// before two poses were observed, and when the last two are equal (the camera is at rest).
  std::vector<Camera> predict(std::uint32_t steps) const;
  void reset() noexcept;

 private:
  std::optional<Camera> last_, previous_;
};

/// Bricks a view of `scene` (its camera, viewport, lod_error_px and channels' level ranges) may
/// sample, coarsest level first, nearer bricks first within a level: a brick is listed for a
/// channel when its box (grown by one voxel of its level, for trilinear filtering) intersects the
/// view frustum and its level lies between the levels the LOD rule of docs/rendering.md selects
/// at the box's nearest and farthest view depth, clamped to the channel's level range. This is
/// conservative: it ignores occlusion, early ray termination and empty space, so it lists a
/// superset of what the traversal would request. `want` filters keys (e.g. already resident);
/// enumeration stops after `max_bricks` wanted keys. Throws what CameraRays throws for a bad
/// camera or viewport.
std::vector<BrickKey> view_bricks(const BrickHierarchy& hierarchy, const Scene& scene,
                                  std::size_t max_bricks,
                                  const std::function<bool(BrickKey)>& want = {});

}  // namespace resoct
