#pragma once
// The tests' oracle is the library's dense reference renderer
// (resoct/render/reference_renderer.hpp); the tests use its names unqualified in their namespace.
#include "resoct/render/reference_renderer.hpp"

namespace resoct::test {
using namespace resoct::reference;
}  // namespace resoct::test
