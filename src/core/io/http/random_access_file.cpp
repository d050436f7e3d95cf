#include "resoct/io/http/open_random_access_file.hpp"

#include <cctype>
#include <limits>
#include <optional>
#include <utility>

#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/http/http_store.hpp"

namespace resoct {

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percent_decode(std::string_view s, const std::string& url) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '%') {
      out.push_back(s[i]);
      continue;
    }
    const int hi = i + 2 < s.size() ? hex_value(s[i + 1]) : -1;
    const int lo = i + 2 < s.size() ? hex_value(s[i + 2]) : -1;
    if (hi < 0 || lo < 0) throw invalid_parameter("url", "bad percent-escape in '" + url + "'");
    out.push_back(char(hi * 16 + lo));
    i += 2;
  }
  return out;
}

/// An object of an HttpStore read by Range requests.
class HttpFile final : public RandomAccessFile {
 public:
  HttpFile(std::shared_ptr<const HttpStore> store, std::string key, std::string name)
      : url_(std::move(name)), key_(std::move(key)), store_(std::move(store)) {
    check_store_key(key_);
    const std::optional<std::uint64_t> size = store_->size(key_);
    if (!size) throw file_error(ErrorCode::io, url_, 0, "not found (HTTP 404)");
    size_ = *size;
  }

  const std::string& path() const noexcept override { return url_; }
  std::uint64_t size() const noexcept override { return size_; }

  void read_at(std::uint64_t offset, std::span<std::byte> out) const override {
    // Checked here like a local file: a request past the end is the file's truncation, not the
    // server's business.
    if (offset > size_ || out.size() > size_ - offset) {
      throw file_error(ErrorCode::truncated, url_, offset,
                       "read of " + std::to_string(out.size()) + " bytes runs past the end (" +
                           std::to_string(size_) + " bytes)");
    }
    store_->read_range(key_, offset, out);
  }

 private:
  std::string url_;
  std::string key_;
  std::shared_ptr<const HttpStore> store_;
  std::uint64_t size_ = 0;
};

/// The URL's directory as an HttpStore's base and its last component, decoded, as the key.
std::unique_ptr<RandomAccessFile> open_http_url(const std::string& url,
                                                const HttpOptions& options) {
  if (url.find_first_of("?#") != std::string::npos) {
    throw invalid_parameter("url", "'" + url + "' has a query or fragment, which is unsupported");
  }
  const std::size_t scheme_end = url.find("://") + 3;
  const std::size_t slash = url.find_last_of('/');
  if (slash == std::string::npos || slash < scheme_end || slash + 1 == url.size()) {
    throw invalid_parameter("url", "'" + url + "' does not name a file on a server");
  }
  std::string key = percent_decode(std::string_view(url).substr(slash + 1), url);
  check_store_key(key);
  auto store = std::make_shared<HttpStore>(UrlMap{url.substr(0, slash), {}}, options);
  return std::make_unique<HttpFile>(std::move(store), std::move(key), url);
}

}  // namespace

std::unique_ptr<RandomAccessFile> open_random_access_file(const std::string& path_or_url,
                                                          const HttpOptions& http) {
  if (is_http_url(path_or_url)) return open_http_url(path_or_url, http);
  return std::make_unique<ReadFile>(path_or_url);
}

std::unique_ptr<RandomAccessFile> open_http_object(std::shared_ptr<const HttpStore> store,
                                                   std::string key, std::string name) {
  return std::make_unique<HttpFile>(std::move(store), std::move(key), std::move(name));
}

std::unique_ptr<RandomAccessFile> open_random_access_file(const std::string& path_or_url) {
  return open_random_access_file(path_or_url, HttpOptions{});
}

}  // namespace resoct
