#pragma once
// Brick layouts and cameras shared by the CPU rendering tests, so that their scenes stay
// comparable (the same bricks, the same oblique view) across files.

#include <glm/vec3.hpp>

#include "resoct/scene/camera.hpp"
#include "resoct/volume/hierarchy.hpp"

namespace resoct::test {

/// 8^3 bricks with a one-voxel halo: small volumes get several levels and many bricks.
inline BrickLayout bricks8() {
  BrickLayout l;
  l.brick_size = glm::uvec3(8);
  l.halo = 1;
  return l;
}

/// A perspective view from above one corner of the unit box, looking at its centre.
inline Camera oblique_camera() {
  Camera c;
  c.eye = {1.9, 1.3, 2.1};
  c.target = {0.5, 0.5, 0.5};
  c.fov_deg = 35.0;
  return c;
}

}  // namespace resoct::test
