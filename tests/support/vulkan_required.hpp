#pragma once
// The one way a test gives up for want of Vulkan. Without a loader, an ICD or a device every
// Vulkan test skips, and a suite of skips is green: a CI machine whose lavapipe broke would
// report success while testing nothing on the GPU path. RESOCT_REQUIRE_VULKAN=1 (set by
// scripts/test.sh, docs/testing.md) turns each such skip into a failure. Header only: the test
// support library does not link Vulkan, and the tool tests only run resoct-render.

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

namespace resoct::test {

/// True when the environment demands that Vulkan works (RESOCT_REQUIRE_VULKAN=1).
inline bool vulkan_required() {
  const char* v = std::getenv("RESOCT_REQUIRE_VULKAN");
  return v != nullptr && std::strcmp(v, "1") == 0;
}

}  // namespace resoct::test

/// In a test body or SetUp(): skips with `why` (streamed), or fails with it when
/// RESOCT_REQUIRE_VULKAN=1. Returns from the function either way, like GTEST_SKIP().
#define RESOCT_SKIP_WITHOUT_VULKAN(why)                                               \
  do {                                                                                \
    if (::resoct::test::vulkan_required()) {                                          \
      GTEST_FAIL() << "RESOCT_REQUIRE_VULKAN=1, but Vulkan is unavailable: " << why;  \
    } else {                                                                          \
      GTEST_SKIP() << why << " (set RESOCT_REQUIRE_VULKAN=1 to make this a failure)"; \
    }                                                                                 \
  } while (0)
