#pragma once
/// \file
/// POSIX file access for resoct's own file formats: a read handle with positional reads (no
/// shared file position, so many threads can read at once) and an atomic writer that makes a
/// file appear at its final path only when it is complete.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "resoct/base/random_access_file.hpp"

namespace resoct {

/// A file opened for reading. Move-only; closes on destruction.
/// Thread-safety: read_at() and size() may be called from any number of threads at once.
class ReadFile final : public RandomAccessFile {
 public:
  /// Opens `path`; throws Error(io) naming the path when it does not exist or cannot be read.
  explicit ReadFile(std::string path);
  ReadFile(ReadFile&& o) noexcept;
  ReadFile& operator=(ReadFile&& o) noexcept;
  ReadFile(const ReadFile&) = delete;
  ReadFile& operator=(const ReadFile&) = delete;
  ~ReadFile() override;

  const std::string& path() const noexcept override { return path_; }
  /// Size in bytes at the time of opening.
  std::uint64_t size() const noexcept override { return size_; }

  /// Reads exactly out.size() bytes starting at `offset` (pread). Throws
  /// file_error(truncated, path, offset, ...) when the file ends first and Error(io) when the
  /// operating system fails.
  void read_at(std::uint64_t offset, std::span<std::byte> out) const override;

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

/// Writes a file atomically: the bytes go to a temporary file in the destination's directory,
/// and commit() fsyncs it and renames it over `path`. If commit() is never reached (an
/// exception, an early return), the destructor removes the temporary file and `path` is left as
/// it was. Thread-safety: none; use from one thread.
class AtomicFileWriter {
 public:
  /// Creates the temporary file; throws Error(io) naming `path` when the directory does not
  /// exist or is not writable.
  explicit AtomicFileWriter(std::string path);
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  ~AtomicFileWriter();

  const std::string& path() const noexcept { return path_; }
  const std::string& temp_path() const noexcept { return temp_path_; }
  /// Bytes appended so far (the offset the next append() writes at).
  std::uint64_t position() const noexcept { return position_; }

  /// Writes at the current position and advances it (buffered).
  void append(std::span<const std::byte> bytes);
  /// Overwrites already-reserved bytes, e.g. a header that is only known at the end.
  void write_at(std::uint64_t offset, std::span<const std::byte> bytes);
  /// Flushes, fsyncs, renames the temporary file to path() and fsyncs the directory. Throws
  /// Error(io) on failure (the temporary file is then still removed by the destructor).
  void commit();

 private:
  void flush();
  void write_fully(std::uint64_t offset, std::span<const std::byte> bytes);

  std::string path_;
  std::string temp_path_;
  int fd_ = -1;
  bool committed_ = false;
  std::uint64_t position_ = 0;
  std::uint64_t buffer_start_ = 0;
  std::vector<std::byte> buffer_;
};

}  // namespace resoct
