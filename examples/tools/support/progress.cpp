#include "support/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace resoct::tools {

Progress::Progress(std::string label, std::uint64_t total)
    : label_(std::move(label)),
      total_(total == 0 ? 1 : total),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  finish();
}

void Progress::advance(std::uint64_t n) {
  done_.fetch_add(n, std::memory_order_relaxed);
  const auto now = std::chrono::steady_clock::now();
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;
  if (tty_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(false);
}

void Progress::finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  draw(true);
}

void Progress::draw(bool final) {
  const std::uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
  const double frac = double(done) / double(total_);
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = int(frac * kWidth);
    std::string bar(std::size_t(filled), '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "\r%s [%s] %5.1f%% %llu/%llu %.1fs", label_.c_str(), bar.c_str(),
                 frac * 100.0, static_cast<unsigned long long>(done),
                 static_cast<unsigned long long>(total_), secs);
    if (final) std::fputc('\n', stderr);
  } else {
    const int decile = int(frac * 10.0);
    if (decile == last_decile_ && !final) return;
    if (final && decile == last_decile_ && done == total_) return;
    last_decile_ = decile;
    std::fprintf(stderr, "%s: %3d%% (%llu/%llu) %.1fs\n", label_.c_str(), int(frac * 100.0),
                 static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_),
                 secs);
  }
  std::fflush(stderr);
}

}  // namespace resoct::tools
