#include "support/generated_data.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <gtest/gtest.h>

#include "support/tool_process.hpp"

namespace resoct::test {

std::string python_generated_dir(const std::string& root, const std::string& name,
                                 const std::string& script) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(root) / name;
  const std::string text = slurp(script);
  if (text.empty()) {
    ADD_FAILURE() << "cannot read generator " << script;
    return {};
  }
  // The stamp holds the script text: an edited script regenerates the data.
  if (slurp((dir / ".generator").string()) == text) return dir.string();
  std::error_code ec;
  fs::create_directories(dir.parent_path(), ec);
  const fs::path tmp = dir.string() + ".tmp." + std::to_string(::getpid());
  fs::remove_all(tmp, ec);
  const std::string cmd = "/usr/bin/python3 " + shell_quote(script) + " " +
                          shell_quote(tmp.string()) + " >" + shell_quote(tmp.string() + ".log") +
                          " 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << "generator failed: " << cmd << "\n" << slurp(tmp.string() + ".log");
    return {};
  }
  fs::remove(tmp.string() + ".log", ec);
  std::ofstream(tmp / ".generator", std::ios::binary) << text;
  if (slurp((dir / ".generator").string()) != text) {
    // Stale or absent: replace it. A concurrent process may win the rename; its data is equal.
    const fs::path old = dir.string() + ".old." + std::to_string(::getpid());
    fs::rename(dir, old, ec);
    fs::rename(tmp, dir, ec);
    fs::remove_all(old, ec);
  }
  fs::remove_all(tmp, ec);
  return dir.string();
}

}  // namespace resoct::test
