#pragma once
// Runs a command-line tool as a child process for the tool tests, with stdout and stderr captured
// in files (so stderr is not a TTY and tools print plain progress lines).

#include <string>

namespace resoct::test {

struct ToolRun {
  int exit_code = -1;  ///< -1 when the process did not exit normally
  std::string out;
  std::string err;
};

/// Runs `tool args` (args are passed to the shell as written) with captures placed in `dir`.
ToolRun run_tool_process(const std::string& dir, const std::string& tool, const std::string& args);

/// Single-quotes a string for the shell.
std::string shell_quote(const std::string& s);

/// The whole content of a file ("" when it cannot be read).
std::string slurp(const std::string& path);

}  // namespace resoct::test
