#pragma once
// Starts tests/support/s3_test_server.mjs (s3rver, an S3-compatible server in node, from
// tests/npm/node_modules) on loopback for the object-store tests. The npm tools are installed by
// scripts/install-test-tools.sh; without them the tests skip, unless RESOCT_REQUIRE_NPM=1 (set
// by scripts/test.sh, as RESOCT_REQUIRE_VULKAN is) turns the skip into a failure, so that a CI
// run whose install broke does not pass while testing nothing.

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "loopback_server_process.hpp"

namespace resoct::test {

/// s3rver's built-in account.
inline constexpr const char* kS3AccessKey = "S3RVER";
inline constexpr const char* kS3Secret = "S3RVER";

/// True when the environment demands the npm test tools (RESOCT_REQUIRE_NPM=1).
inline bool npm_required() {
  const char* v = std::getenv("RESOCT_REQUIRE_NPM");
  return v != nullptr && std::strcmp(v, "1") == 0;
}

/// Why the S3 test server cannot run here, or "" when it can.
inline std::string s3_test_server_missing() {
  const std::filesystem::path s3rver =
      std::filesystem::path(RESOCT_SOURCE_DIR) / "tests/npm/node_modules/s3rver/package.json";
  std::error_code ec;
  if (!std::filesystem::exists(s3rver, ec)) {
    return s3rver.string() + " is missing (run scripts/install-test-tools.sh)";
  }
  if (std::system("node --version >/dev/null 2>&1") != 0) return "node is not on PATH";
  return {};
}

class S3TestServer {
 public:
  /// A bucket and the local directory whose files it holds ("" for an empty bucket).
  using Bucket = std::pair<std::string, std::string>;

  /// Starts s3rver with `buckets` and, when `session_token` is not empty, requires it on signed
  /// requests. Throws std::runtime_error when the server does not start.
  explicit S3TestServer(const std::vector<Bucket>& buckets, const std::string& session_token = {})
      : process_(argv(buckets, session_token), "s3 test server") {}

  int port() const { return process_.port(); }
  /// The endpoint for S3Options::endpoint: "http://127.0.0.1:<port>".
  std::string endpoint() const { return "http://127.0.0.1:" + std::to_string(port()); }

 private:
  static std::vector<std::string> argv(const std::vector<Bucket>& buckets,
                                       const std::string& session_token) {
    std::vector<std::string> a{
        "node", std::string(RESOCT_SOURCE_DIR) + "/tests/support/s3_test_server.mjs"};
    if (!session_token.empty()) {
      a.push_back("--token");
      a.push_back(session_token);
    }
    for (const auto& [name, dir] : buckets) a.push_back(name + "=" + dir);
    return a;
  }

  LoopbackServerProcess process_;
};

}  // namespace resoct::test

/// In a test body or SetUp(): skips when the S3 test server cannot run here, or fails when
/// RESOCT_REQUIRE_NPM=1. Returns from the function either way, like GTEST_SKIP().
#define RESOCT_SKIP_WITHOUT_S3_SERVER()                                                 \
  do {                                                                                  \
    const std::string missing_ = ::resoct::test::s3_test_server_missing();              \
    if (missing_.empty()) break;                                                        \
    if (::resoct::test::npm_required()) {                                               \
      GTEST_FAIL() << "RESOCT_REQUIRE_NPM=1, but " << missing_;                         \
    } else {                                                                            \
      GTEST_SKIP() << missing_ << " (set RESOCT_REQUIRE_NPM=1 to make this a failure)"; \
    }                                                                                   \
  } while (0)
