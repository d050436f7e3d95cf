#pragma once
/// \file
/// A ByteStore over one or more HTTP(S) servers (libcurl): keep-alive connection reuse across
/// threads, timeouts, retries with exponential backoff, Range requests, and a URL map that lets
/// key prefixes (zarr levels, channels, a brick store file) live on different hosts. Requests may
/// be SigV4-signed (HttpOptions::aws_sigv4): S3 stores (s3_store.hpp) are HttpStores.
/// Spec and behaviour: docs/http.md.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "resoct/io/storage/byte_store.hpp"

namespace resoct {

/// Where keys live. A key goes to the route with the longest prefix that matches it on
/// component boundaries ("0" matches "0" and "0/1.2.3", not "01"), else to `base`; the URL is
/// "<route url>/<key>" with the key's bytes outside [A-Za-z0-9._~/-] percent-encoded. Route
/// URLs are mirrors of the same layout: the whole key is appended, the prefix is not removed.
struct UrlMap {
  std::string base;  ///< http:// or https:// URL without a trailing '/'
  std::vector<std::pair<std::string, std::string>> routes;  ///< (key prefix, URL)
};

/// Parses the compact form "URL[,PREFIX=URL]...": exactly one entry without "PREFIX=" (the
/// base), entries separated by ',' (a ',' inside a URL must be written %2C). Example:
/// "http://a/x.zarr,2=http://b/x.zarr,3=http://c/x.zarr". Throws Error(invalid_argument) naming
/// "url_map" for a missing or doubled base, a URL that is not http(s)://host..., or a prefix that
/// is not a valid store key (check_store_key).
UrlMap parse_url_map(std::string_view spec);

/// AWS Signature Version 4 for every request (S3 and S3-compatible stores: MinIO, Ceph, GCS
/// interoperability), computed by libcurl (CURLOPT_AWS_SIGV4 "aws:amz:<region>:<service>").
/// s3_store.hpp fills it from options, the environment or a credentials file. The secret and the
/// token never appear in messages.
struct AwsSigV4 {
  std::string region = "us-east-1";
  std::string service = "s3";
  std::string access_key_id;
  std::string secret_access_key;
  std::string session_token;  ///< temporary credentials: sent, and signed, as x-amz-security-token
};

/// Network behaviour of an HttpStore. Every limit bounds one attempt; a request makes at most
/// 1 + retries attempts, so it ends within (1 + retries) * total_timeout_ms plus the backoff.
struct HttpOptions {
  std::uint32_t connect_timeout_ms = 5000;
  std::uint32_t total_timeout_ms = 60000;
  /// An attempt is abandoned when it transfers fewer than low_speed_bytes per second for
  /// low_speed_time_s seconds (a stalled server cannot hold a loader thread for the whole
  /// total timeout). 0 bytes disables the check.
  std::uint32_t low_speed_bytes = 1024;
  std::uint32_t low_speed_time_s = 10;
  /// Extra attempts after a transient failure: HTTP 408, 429, 5xx, timeouts, refused or reset
  /// connections, truncated bodies. Never for 404/410 (absence) or other 4xx.
  std::uint32_t retries = 3;
  std::uint32_t backoff_initial_ms = 100;  ///< wait before the first retry; doubles each time
  std::uint32_t backoff_max_ms = 2000;
  /// Idle connections kept open for reuse (shared by all threads).
  std::uint32_t max_idle_connections = 32;
  /// Origins beyond those of the URL map that a redirect may lead to, e.g.
  /// "https://cdn.example.org" (only scheme, host and port are used). A redirect to any other
  /// origin (another host or port, https to http, another scheme such as file://) fails with
  /// Error(invalid_argument) naming the URL and the target; it is never followed.
  std::vector<std::string> redirect_origins;
  /// Sign requests (S3); unsigned (anonymous) when empty.
  std::optional<AwsSigV4> aws_sigv4;
  /// Throws Error(invalid_argument) naming the field.
  void validate() const;
};

/// Counters since construction.
struct HttpStats {
  std::uint64_t requests = 0;     ///< attempts sent, retries included
  std::uint64_t retries = 0;      ///< attempts after a transient failure
  std::uint64_t connections = 0;  ///< new connections opened (CURLINFO_NUM_CONNECTS summed)
  std::uint64_t bytes = 0;        ///< body bytes kept
};

/// Thread-safety: every member may be called from any number of threads at once; requests of
/// different threads run in parallel on separate easy handles that share one connection cache,
/// one DNS cache and one TLS session cache.
class HttpStore final : public ByteStore {
 public:
  /// Throws Error(invalid_argument) for a bad map or options.
  explicit HttpStore(UrlMap map, HttpOptions options = {});
  ~HttpStore() override;
  HttpStore(const HttpStore&) = delete;
  HttpStore& operator=(const HttpStore&) = delete;

  /// GET of the whole object. nullopt for HTTP 404/410, except a 404 whose S3 error code is
  /// NoSuchBucket (a missing bucket is a mistake, not an absent zarr chunk: Error(io)). Throws
  /// Error(out_of_range) naming the URL when the body exceeds max_bytes (the transfer is aborted as
  /// soon as Content-Length or the received bytes exceed it), Error(truncated) naming the URL when
  /// the body is shorter than its Content-Length, Error(io) naming the URL and the reason for any
  /// other failure.
  std::optional<std::vector<std::byte>> get(std::string_view key,
                                            std::uint64_t max_bytes) const override;
  /// GET with "Range: bytes=offset-(offset+size-1)". A 206 answer must carry the matching
  /// Content-Range; a 200 answer (server without Range support) is skipped to `offset` and
  /// aborted after `size` bytes. Throws Error(truncated) naming the URL and offset when the object
  /// is shorter (also for 416), Error(io) for 404 and failures as get().
  std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                   std::uint64_t size) const override;
  /// get_range, but nullopt for HTTP 404/410.
  std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                             std::uint64_t offset,
                                                             std::uint64_t size) const override;
  /// GET with a suffix range "Range: bytes=-size"; the object size comes from the 206 answer's
  /// Content-Range. A server that answers it with 200 (the transfer is aborted after the
  /// headers), 400, 416 or 501 does not do suffix ranges: the store remembers that and reads
  /// the size with HEAD and the bytes with a first-last range from then on. nullopt for
  /// 404/410; Error(truncated) naming the URL when the object is shorter than `size`.
  std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const override;
  /// Writes the range into `out` (size = out.size()) without an intermediate vector.
  void read_range(std::string_view key, std::uint64_t offset, std::span<std::byte> out) const;
  /// Object size from a HEAD request's Content-Length; nullopt for 404/410. Throws as get().
  std::optional<std::uint64_t> size(std::string_view key) const;
  /// The URL of `key`.
  std::string location(std::string_view key) const override;

  const UrlMap& url_map() const noexcept;
  const HttpOptions& options() const noexcept;
  HttpStats stats() const;

 private:
  /// A first-last range request into `out`; false when the object is absent.
  bool read_range_if_present(std::string_view key, std::uint64_t offset,
                             std::span<std::byte> out) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// True for "http://..." and "https://..." (case-insensitive scheme).
bool is_http_url(std::string_view s) noexcept;

/// A shared HttpStore for a url map spec (parse_url_map).
std::shared_ptr<HttpStore> open_http_store(std::string_view url_map_spec, HttpOptions options = {});

}  // namespace resoct
