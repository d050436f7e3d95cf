#pragma once
// Bit-exact comparison of two brick sources over every brick of every channel and level.

#include "resoct/sources/brick_source.hpp"

namespace resoct::test {

/// Asserts (gtest) that both sources have the same hierarchy and identical brick bytes.
void expect_same_bricks(const BrickSource& a, const BrickSource& b);

}  // namespace resoct::test
