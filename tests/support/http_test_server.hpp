#pragma once
// Starts tests/support/http_test_server.py on loopback for the HTTP tests and benchmarks. Header
// only, so that benchmark programs (which do not link the test support library) can use it too.
// The server binds port 0 and reports its port on its first output line; it exits when its
// standard input closes, so it dies with the test process even when that is killed.

#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <fcntl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "resoct/http_store.hpp"

namespace resoct::test {

class HttpTestServer {
 public:
  /// Serves `root` with the script at `script`. Throws std::runtime_error when the server does
  /// not start.
  HttpTestServer(const std::string& script, const std::string& root) {
    int to_child[2], from_child[2];
    if (::pipe2(to_child, O_CLOEXEC) != 0 || ::pipe2(from_child, O_CLOEXEC) != 0) {
      throw std::runtime_error("pipe failed");
    }
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      ::dup2(to_child[0], 0);
      ::dup2(from_child[1], 1);
      const char* python = "/usr/bin/python3";
      ::execl(python, python, script.c_str(), root.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(to_child[0]);
    ::close(from_child[1]);
    stdin_fd_ = to_child[1];
    std::string line;
    char c = 0;
    while (::read(from_child[0], &c, 1) == 1 && c != '\n') line.push_back(c);
    ::close(from_child[0]);
    if (line.rfind("PORT ", 0) != 0) {
      stop();
      throw std::runtime_error("http test server did not start (" + script + "): '" + line + "'");
    }
    port_ = std::stoi(line.substr(5));
  }
  ~HttpTestServer() { stop(); }
  HttpTestServer(const HttpTestServer&) = delete;
  HttpTestServer& operator=(const HttpTestServer&) = delete;

  int port() const { return port_; }
  /// "http://127.0.0.1:<port>/<mode>" (see the script for the modes).
  std::string base(const std::string& mode = "ok") const {
    return "http://127.0.0.1:" + std::to_string(port_) + "/" + mode;
  }

  /// The script next to this header in the source tree: RESOCT_SOURCE_DIR when the including
  /// target defines it, else found by walking up from the running executable (benchmarks).
  static std::string default_script() {
    const std::string rel = "tests/support/http_test_server.py";
#ifdef RESOCT_SOURCE_DIR
    return std::string(RESOCT_SOURCE_DIR) + "/" + rel;
#else
    if (const char* env = std::getenv("RESOCT_SOURCE_DIR")) return std::string(env) + "/" + rel;
    std::error_code ec;
    auto dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
    for (int i = 0; i < 6 && !dir.empty(); ++i, dir = dir.parent_path()) {
      if (std::filesystem::exists(dir / rel, ec)) return (dir / rel).string();
      if (dir == dir.parent_path()) break;
    }
    throw std::runtime_error("cannot find " + rel + "; set RESOCT_SOURCE_DIR");
#endif
  }

 private:
  void stop() {
    if (stdin_fd_ >= 0) ::close(stdin_fd_);
    stdin_fd_ = -1;
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
  }

  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int port_ = 0;
};

/// HTTP options for tests against HttpTestServer: short timeouts and backoff, two retries, so
/// that failure cases end in seconds.
inline HttpOptions fast_http_options() {
  HttpOptions o;
  o.connect_timeout_ms = 1000;
  o.total_timeout_ms = 2000;
  o.low_speed_time_s = 1;
  o.retries = 2;
  o.backoff_initial_ms = 10;
  o.backoff_max_ms = 40;
  return o;
}

}  // namespace resoct::test
