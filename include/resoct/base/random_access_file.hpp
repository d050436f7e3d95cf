#pragma once
/// \file
/// Positional reads from a file of known size, wherever it lives: a local file (ReadFile, pread)
/// or an object on an HTTP server (Range requests through an HttpStore). The brick store reader
/// reads through this interface, so a store can be rendered straight from a web server.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace resoct {

struct HttpOptions;
class HttpStore;

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

/// Opens a local path (ReadFile) or an http(s):// URL. For a URL the size comes from a HEAD
/// request and reads are Range requests with `http` (retries, timeouts: HttpOptions). The URL's
/// last path component names the object (percent-escapes are decoded and re-encoded); URLs with
/// a query or fragment are rejected with Error(invalid_argument). Throws Error(io) naming the
/// path or URL when it does not exist or cannot be read.
std::unique_ptr<RandomAccessFile> open_random_access_file(const std::string& path_or_url,
                                                          const HttpOptions& http);
/// The object `key` of `store` (HEAD for its size, then Range requests); `name` is its path()
/// ("s3://bucket/key"), which messages name. Throws as above.
std::unique_ptr<RandomAccessFile> open_http_object(std::shared_ptr<const HttpStore> store,
                                                   std::string key, std::string name);
/// As above with default HttpOptions.
std::unique_ptr<RandomAccessFile> open_random_access_file(const std::string& path_or_url);

}  // namespace resoct
