#include "atomic_write.hpp"

#include <cerrno>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "resoct/error.hpp"

namespace resoct::detail {
namespace {

Error io_error(const std::string& path, const std::string& what, int err) {
  return Error(ErrorCode::io,
               path + ": " + what + (err != 0 ? ": " + std::string(std::strerror(err)) : ""));
}

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

void write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write) {
  std::string tmp = path + ".tmp-XXXXXX";
  std::vector<char> name(tmp.begin(), tmp.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) throw io_error(path, "cannot create temporary file", errno);
  tmp.assign(name.data());

  std::FILE* file = ::fdopen(fd, "wb");
  if (file == nullptr) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    throw io_error(path, "cannot open temporary file", err);
  }
  // From here on every failure path closes the stream and removes the temporary.
  auto abandon = [&](const std::string& what, int err) {
    std::fclose(file);
    ::unlink(tmp.c_str());
    return io_error(path, what, err);
  };
  bool written = false;
  try {
    written = write(file);
  } catch (...) {
    std::fclose(file);
    ::unlink(tmp.c_str());
    throw;
  }
  if (!written) throw abandon("write failed", errno);
  if (std::fflush(file) != 0) throw abandon("write failed", errno);
  if (::fsync(::fileno(file)) != 0) throw abandon("fsync failed", errno);
  if (std::fclose(file) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw io_error(path, "close failed", err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw io_error(path, "rename failed", err);
  }
  // Make the rename itself durable; failure here cannot be undone and the data is in place.
  const int dir = ::open(directory_of(path).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace resoct::detail
