#include "support/generated_data.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <gtest/gtest.h>

#include "support/tool_process.hpp"

namespace resoct::test {

namespace {

/// An exclusive flock held for the lifetime of the object (released when the fd closes).
class FileLock {
 public:
  explicit FileLock(const std::string& path) : fd_(::open(path.c_str(), O_CREAT | O_RDWR, 0644)) {
    if (fd_ >= 0) ::flock(fd_, LOCK_EX);
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock() {
    if (fd_ >= 0) ::close(fd_);
  }

 private:
  int fd_;
};

}  // namespace

std::string python_generated_dir(const std::string& root, const std::string& name,
                                 const std::string& script) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(root) / name;
  const std::string text = slurp(script);
  if (text.empty()) {
    ADD_FAILURE() << "cannot read generator " << script;
    return {};
  }
  std::error_code ec;
  fs::create_directories(dir.parent_path(), ec);
  // Test processes run in parallel; the first one generates while the others wait.
  const FileLock lock(dir.string() + ".lock");
  // The stamp holds the script text: an edited script regenerates the data.
  if (slurp((dir / ".generator").string()) == text) return dir.string();
  const fs::path tmp = dir.string() + ".tmp";
  fs::remove_all(tmp, ec);
  const std::string log = tmp.string() + ".log";
  const std::string cmd = "/usr/bin/python3 " + shell_quote(script) + " " +
                          shell_quote(tmp.string()) + " >" + shell_quote(log) + " 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << "generator failed: " << cmd << "\n" << slurp(log);
    return {};
  }
  fs::remove(log, ec);
  std::ofstream(tmp / ".generator", std::ios::binary) << text;
  fs::remove_all(dir, ec);
  fs::rename(tmp, dir, ec);
  if (ec) {
    ADD_FAILURE() << "cannot move " << tmp << " to " << dir << ": " << ec.message();
    return {};
  }
  return dir.string();
}

}  // namespace resoct::test
