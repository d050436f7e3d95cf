#pragma once
// The tools' check of an output path before any work starts, so that a typo in an output path
// fails at once, before minutes of converting or rendering, and before any other output is
// replaced.

#include <string>

namespace resoct::tools {

/// Throws Error(io) naming `path` when its directory does not exist (or is not a directory) or
/// when `path` itself is a directory; Error(invalid_argument) naming `option` for an empty path.
void check_output_path(const std::string& option, const std::string& path);

}  // namespace resoct::tools
