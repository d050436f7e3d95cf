#include "support/brick_compare.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace resoct::test {

void expect_same_bricks(const BrickSource& a, const BrickSource& b) {
  // Everything but VolumeDesc::origin: brick stores do not persist it (docs/formats.md,
  // "Physical placement"), so a converted NIfTI reads back at origin 0.
  ASSERT_EQ(a.hierarchy().layout(), b.hierarchy().layout());
  VolumeDesc va = a.volume(), vb = b.volume();
  va.origin = vb.origin = glm::dvec3(0.0);
  ASSERT_EQ(va, vb);
  const std::size_t bytes = a.hierarchy().layout().padded_voxels() * voxel_size(a.volume().type);
  std::vector<std::byte> x(bytes), y(bytes);
  for (std::uint32_t c = 0; c < a.volume().channels; ++c) {
    for (std::uint64_t i = 0; i < a.hierarchy().bricks_per_channel(); ++i) {
      const BrickKey key = a.hierarchy().key_from_linear(c, i);
      a.read_brick(key, x);
      b.read_brick(key, y);
      ASSERT_EQ(std::memcmp(x.data(), y.data(), bytes), 0) << "channel " << c << " brick " << i;
    }
  }
}

}  // namespace resoct::test
