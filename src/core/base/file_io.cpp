#include "resoct/base/file_io.hpp"

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {
std::string os_error(int err) {
  return std::strerror(err);
}

// Appends are collected up to this size so that many small compressed bricks cost few syscalls.
constexpr std::size_t kWriteBuffer = std::size_t(1) << 20;

std::string parent_directory(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}
}  // namespace

ReadFile::ReadFile(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    throw file_error(ErrorCode::io, path_, 0, "cannot open for reading: " + os_error(errno));
  }
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    throw file_error(ErrorCode::io, path_, 0, "cannot query the size: " + os_error(err));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw file_error(ErrorCode::io, path_, 0, "not a regular file");
  }
  size_ = std::uint64_t(st.st_size);
}

ReadFile::ReadFile(ReadFile&& o) noexcept
    : path_(std::move(o.path_)), fd_(std::exchange(o.fd_, -1)), size_(o.size_) {}

ReadFile& ReadFile::operator=(ReadFile&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(o.path_);
    fd_ = std::exchange(o.fd_, -1);
    size_ = o.size_;
  }
  return *this;
}

ReadFile::~ReadFile() {
  if (fd_ >= 0) ::close(fd_);
}

void ReadFile::read_at(std::uint64_t offset, std::span<std::byte> out) const {
  std::size_t done = 0;
  while (done < out.size()) {
    const std::uint64_t at = offset + done;
    const ssize_t n = ::pread(fd_, out.data() + done, out.size() - done, off_t(at));
    if (n < 0) {
      if (errno == EINTR) continue;
      throw file_error(ErrorCode::io, path_, at, "read failed: " + os_error(errno));
    }
    if (n == 0) {
      throw file_error(ErrorCode::truncated, path_, at,
                       "file ends " + std::to_string(out.size() - done) +
                           " bytes before the end of a " + std::to_string(out.size()) +
                           "-byte read at offset " + std::to_string(offset));
    }
    done += std::size_t(n);
  }
}

AtomicFileWriter::AtomicFileWriter(std::string path) : path_(std::move(path)) {
  // Same directory as the target: rename() is only atomic within one file system.
  std::string tmpl = path_ + ".tmp-XXXXXX";
  fd_ = ::mkstemp(tmpl.data());
  if (fd_ < 0) {
    throw file_error(ErrorCode::io, path_, 0,
                     "cannot create a temporary file next to it: " + os_error(errno));
  }
  temp_path_ = std::move(tmpl);
  // mkstemp creates 0600; a finished file should be as readable as any other output file.
  ::fchmod(fd_, 0644);
  buffer_.reserve(kWriteBuffer);
}

AtomicFileWriter::~AtomicFileWriter() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temp_path_.empty()) ::unlink(temp_path_.c_str());
}

void AtomicFileWriter::write_fully(std::uint64_t offset, std::span<const std::byte> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
    if (n < 0) {
      if (errno == EINTR) continue;
      throw file_error(ErrorCode::io, temp_path_, offset + done,
                       "write failed: " + os_error(errno));
    }
    done += std::size_t(n);
  }
}

void AtomicFileWriter::flush() {
  if (buffer_.empty()) return;
  write_fully(buffer_start_, buffer_);
  buffer_start_ += buffer_.size();
  buffer_.clear();
}

void AtomicFileWriter::append(std::span<const std::byte> bytes) {
  if (buffer_.size() + bytes.size() > kWriteBuffer) flush();
  if (bytes.size() >= kWriteBuffer) {
    write_fully(buffer_start_, bytes);
    buffer_start_ += bytes.size();
  } else {
    buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  }
  position_ += bytes.size();
}

void AtomicFileWriter::write_at(std::uint64_t offset, std::span<const std::byte> bytes) {
  if (offset + bytes.size() > position_) {
    throw invalid_parameter("offset", "write_at must stay within the " + std::to_string(position_) +
                                          " bytes appended so far");
  }
  flush();
  write_fully(offset, bytes);
}

void AtomicFileWriter::commit() {
  if (committed_) return;
  flush();
  if (::fsync(fd_) != 0) {
    throw file_error(ErrorCode::io, temp_path_, position_, "fsync failed: " + os_error(errno));
  }
  if (::close(fd_) != 0) {
    fd_ = -1;
    throw file_error(ErrorCode::io, temp_path_, position_, "close failed: " + os_error(errno));
  }
  fd_ = -1;
  if (::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    throw file_error(ErrorCode::io, path_, 0,
                     "cannot rename " + temp_path_ + " into place: " + os_error(errno));
  }
  committed_ = true;
  // Make the rename itself durable; failure here leaves a complete file, so it is not an error.
  const int dir = ::open(parent_directory(path_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace resoct
