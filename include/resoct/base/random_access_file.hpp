#pragma once
/// \file
/// Positional reads from a file of known size, wherever it lives: a local file (ReadFile, pread)
/// or an object on an HTTP server (Range requests through an HttpStore). The brick store reader
/// reads through this interface, so a store can be rendered straight from a web server. Opening
/// one by path or URL is I/O (resoct::io): io/http/open_random_access_file.hpp.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace resoct {

/// Thread-safety: implementations allow read_at(), size() and path() from any number of threads
/// at once (nothing shares a file position).
class RandomAccessFile {
 public:
  virtual ~RandomAccessFile() = default;
  /// The path or URL, for messages.
  virtual const std::string& path() const noexcept = 0;
  /// Size in bytes at the time of opening.
  virtual std::uint64_t size() const noexcept = 0;
  /// Reads exactly out.size() bytes at `offset`. Throws file_error(truncated, path, offset, ...)
  /// when the file ends first, and Error(io) (naming the path or URL) when the read fails.
  virtual void read_at(std::uint64_t offset, std::span<std::byte> out) const = 0;
};

}  // namespace resoct
