#pragma once
// Starts tests/support/http_test_server.py on loopback for the HTTP tests and benchmarks. Header
// only, so that benchmark programs (which do not link the test support library) can use it too.

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "loopback_server_process.hpp"
#include "resoct/io/http/http_store.hpp"

namespace resoct::test {

class HttpTestServer {
 public:
  /// Serves `root` with the script at `script`. Throws std::runtime_error when the server does
  /// not start.
  HttpTestServer(const std::string& script, const std::string& root)
      : process_({"/usr/bin/python3", script, root}, "http test server (" + script + ")") {}

  int port() const { return process_.port(); }
  /// The body of GET /<path> (a control path such as "_stats" or "_chaos/300/1"); throws as
  /// HttpStore does, and std::runtime_error when it is absent.
  std::string get(const std::string& path) const {
    HttpStore s(parse_url_map("http://127.0.0.1:" + std::to_string(port())));
    const auto body = s.get(path, 1 << 20);
    if (!body) throw std::runtime_error("http test server: no " + path);
    return std::string(reinterpret_cast<const char*>(body->data()), body->size());
  }
  /// "http://127.0.0.1:<port>/<mode>" (see the script for the modes).
  std::string base(const std::string& mode = "ok") const {
    return "http://127.0.0.1:" + std::to_string(port()) + "/" + mode;
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
  LoopbackServerProcess process_;
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
