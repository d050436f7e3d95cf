#pragma once
// Test data written by a generator script at test time (no binary fixtures in the repository),
// shared by every test process: generated once into the build tree and reused while the script
// is unchanged.

#include <string>

namespace resoct::test {

/// The directory <root>/<name> (tests pass RESOCT_BINARY_DIR "/test-data"), filled by running
/// `/usr/bin/python3 <script> <dir>` unless it already holds the output of the same script
/// text. Concurrent test processes are safe: each generates into a private directory and
/// renames it into place. Fails the calling test (gtest ASSERT semantics via the returned
/// empty string plus an ADD_FAILURE) when the script fails.
std::string python_generated_dir(const std::string& root, const std::string& name,
                                 const std::string& script);

}  // namespace resoct::test
