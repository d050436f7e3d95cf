#pragma once
// Bit-exact comparison of two brick sources over every brick of every channel and level.

#include "resoct/brick_source.hpp"

namespace resoct::test {

/// Asserts (gtest) that both sources have the same brick layout, the same VolumeDesc but for
/// `origin` (brick stores do not persist it), and identical brick bytes.
void expect_same_bricks(const BrickSource& a, const BrickSource& b);

}  // namespace resoct::test
