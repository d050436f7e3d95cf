#pragma once
// Assertion helpers for resoct::Error: the code and a fragment of the message must both match,
// so a test cannot pass on an unrelated failure.

#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "resoct/base/error.hpp"

namespace resoct::test {

/// Succeeds when fn throws resoct::Error with `code` and a message containing `needle`.
::testing::AssertionResult throws_error(const std::function<void()>& fn, ErrorCode code,
                                        const std::string& needle);

}  // namespace resoct::test

#define EXPECT_RESOCT_ERROR(stmt, code, needle) \
  EXPECT_TRUE(::resoct::test::throws_error([&] { stmt; }, code, needle))
