#pragma once
/// \file
/// Opening a RandomAccessFile by local path or http(s):// URL (resoct::io; the interface itself is
/// in base/, below the layers that read through it).

#include <memory>
#include <string>

#include "resoct/base/random_access_file.hpp"

namespace resoct {

struct HttpOptions;
class HttpStore;

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
