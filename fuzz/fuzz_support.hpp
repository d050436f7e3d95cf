#pragma once
// Shared by every fuzz target: the contract (resoct::Error is an ordinary outcome of bad input,
// anything else is a finding) and a scratch file for parsers that only read from a path.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <exception>
#include <string_view>

#include "resoct/sources/brick_source.hpp"
#include "resoct/base/error.hpp"

namespace resoct::fuzz {

/// Reports a violated property (e.g. a round trip that changes the value) and aborts, which
/// libFuzzer records as a crash and the replay test as a failure.
[[noreturn]] inline void fail(std::string_view what) {
  std::fprintf(stderr, "fuzz property violated: %.*s\n", int(what.size()), what.data());
  std::abort();
}

/// Runs `f`; resoct::Error is the documented answer to bad input and is swallowed. Any other
/// exception (std::out_of_range from a container, nlohmann::json's own errors, bad_alloc, ...)
/// escapes a parser's contract and aborts with its message.
/// With RESOCT_FUZZ_VERBOSE set in the environment, each swallowed resoct::Error is printed
/// (to see which check a seed or a corpus input stops at).
template <typename F>
bool errors_only(F&& f) {
  static const bool verbose = std::getenv("RESOCT_FUZZ_VERBOSE") != nullptr;
  try {
    f();
    return true;
  } catch (const resoct::Error& e) {
    if (verbose) std::fprintf(stderr, "resoct::Error: %s\n", e.what());
    return false;
  } catch (const std::exception& e) {
    fail(std::string("exception other than resoct::Error: ") + e.what());
  } catch (...) {
    fail("non-standard exception");
  }
}

/// Reads up to `max_bricks` bricks of each of the first four channels (each read may throw
/// resoct::Error, which only skips that brick), their metadata, and the region metadata of the
/// whole volume: what a renderer asks of a freshly opened source.
void exercise_source(const BrickSource& src, std::uint64_t max_bricks);

/// One temporary file per process (in $TMPDIR, else /dev/shm, else /tmp), rewritten with each
/// input (for readers that take a path).
class ScratchFile {
 public:
  explicit ScratchFile(const char* stem);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  /// Replaces the whole content with `size` bytes of `data`.
  void write(const std::uint8_t* data, std::size_t size);
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace resoct::fuzz
