#pragma once
// Test data written by a generator script at test time (no binary fixtures in the repository),
// shared by every test process: generated once into the build tree and reused while the script
// is unchanged.

#include <string>

namespace resoct::test {

/// The directory <root>/<name> (tests pass RESOCT_BINARY_DIR "/test-data"), filled by running
/// `/usr/bin/python3 <script> <dir>` unless it already holds the output of the same script
/// text. Concurrent test processes are safe: a lock file next to the directory lets the first
/// one generate (into a temporary directory renamed into place) while the others wait. When
/// the script fails, the calling test fails (ADD_FAILURE) and "" is returned.
std::string python_generated_dir(const std::string& root, const std::string& name,
                                 const std::string& script);

}  // namespace resoct::test
