#pragma once
// A progress bar for long tool runs: a redrawn bar on a terminal, plain percentage lines (at most
// one per 10 %) when stderr is not a TTY, so that logs stay readable.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace resoct::tools {

class Progress {
 public:
  Progress(std::string label, std::uint64_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Thread-safe: adds `n` finished units and redraws at most every 100 ms.
  void advance(std::uint64_t n = 1);
  /// Draws the final state and a newline. Called by the destructor if not called before.
  void finish();

 private:
  void draw(bool final);

  std::string label_;
  std::uint64_t total_;
  std::atomic<std::uint64_t> done_{0};
  std::mutex mutex_;
  bool tty_;
  bool finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace resoct::tools
