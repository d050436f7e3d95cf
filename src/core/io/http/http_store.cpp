#include "resoct/io/http/http_store.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstring>
#include <mutex>
#include <thread>

#include <curl/curl.h>

#include "io/http/http_attempt.hpp"
#include "io/http/http_origin.hpp"
#include "io/http/percent_encoding.hpp"
#include "io/http/s3_error_code.hpp"
#include "resoct/base/error.hpp"

namespace resoct {

namespace {

using detail::Attempt;
using detail::parse_content_range;
using detail::parse_u64;
using detail::transient;

bool starts_with_ci(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[i])) != prefix[i]) return false;
  }
  return true;
}

void check_url(std::string_view url) {
  const std::size_t scheme = starts_with_ci(url, "http://") ? 7 : 8;
  if (!is_http_url(url) || url.size() <= scheme || url[scheme] == '/') {
    throw invalid_parameter("url_map", "'" + std::string(url) + "' is not an http(s)://host URL");
  }
  for (char c : url) {
    if (static_cast<unsigned char>(c) <= 0x20 || c == 0x7F) {
      throw invalid_parameter("url_map",
                              "'" + std::string(url) + "' contains a space or control character");
    }
  }
}

std::string trim_slashes(std::string_view url) {
  while (!url.empty() && url.back() == '/') url.remove_suffix(1);
  return std::string(url);
}

bool prefix_matches(std::string_view prefix, std::string_view key) {
  return key.starts_with(prefix) && (key.size() == prefix.size() || key[prefix.size()] == '/');
}

void global_init() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (curl_global_init(CURL_GLOBAL_DEFAULT) != CURLE_OK) {
      throw Error(ErrorCode::io, "libcurl: curl_global_init failed");
    }
  });
}

/// SHA-256 of the empty body: every request here is a GET or HEAD. S3 requires the payload
/// hash as an x-amz-content-sha256 header on signed requests, which libcurl 7.88 does not add
/// by itself; given as a header it is also what libcurl signs.
constexpr const char* kEmptyPayloadSha256 =
    "x-amz-content-sha256: e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855";

bool has_control_character(std::string_view s) {
  return std::any_of(s.begin(), s.end(),
                     [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; });
}

enum class Outcome { done, absent, retry, fail, redirect, no_suffix };

/// Redirect hops followed per attempt (libcurl's CURLOPT_MAXREDIRS before redirects were
/// followed by hand).
constexpr int kMaxRedirects = 5;

}  // namespace

bool is_http_url(std::string_view s) noexcept {
  return starts_with_ci(s, "http://") || starts_with_ci(s, "https://");
}

UrlMap parse_url_map(std::string_view spec) {
  UrlMap map;
  bool have_base = false;
  std::size_t start = 0;
  while (start <= spec.size()) {
    std::size_t end = spec.find(',', start);
    if (end == std::string_view::npos) end = spec.size();
    const std::string_view entry = spec.substr(start, end - start);
    start = end + 1;
    if (entry.empty())
      throw invalid_parameter("url_map", "empty entry in '" + std::string(spec) + "'");
    if (is_http_url(entry)) {
      if (have_base) {
        throw invalid_parameter("url_map", "more than one base URL in '" + std::string(spec) + "'");
      }
      check_url(entry);
      map.base = trim_slashes(entry);
      have_base = true;
      continue;
    }
    const std::size_t eq = entry.find('=');
    if (eq == std::string_view::npos) {
      throw invalid_parameter("url_map",
                              "entry '" + std::string(entry) + "' is neither a URL nor PREFIX=URL");
    }
    const std::string_view prefix = entry.substr(0, eq);
    const std::string_view url = entry.substr(eq + 1);
    try {
      check_store_key(prefix);
    } catch (const Error&) {
      throw invalid_parameter(
          "url_map", "route prefix '" + std::string(prefix) + "' is not a valid store key");
    }
    check_url(url);
    for (const auto& [p, u] : map.routes) {
      if (p == prefix) {
        throw invalid_parameter("url_map", "route prefix '" + std::string(prefix) + "' repeated");
      }
    }
    map.routes.emplace_back(std::string(prefix), trim_slashes(url));
  }
  if (!have_base) throw invalid_parameter("url_map", "no base URL in '" + std::string(spec) + "'");
  return map;
}

void HttpOptions::validate() const {
  if (connect_timeout_ms == 0) throw invalid_parameter("connect_timeout_ms", "must be > 0");
  if (total_timeout_ms == 0) throw invalid_parameter("total_timeout_ms", "must be > 0");
  if (low_speed_bytes != 0 && low_speed_time_s == 0) {
    throw invalid_parameter("low_speed_time_s", "must be > 0 when low_speed_bytes is set");
  }
  if (retries > 20) throw invalid_parameter("retries", "must be at most 20");
  if (backoff_max_ms < backoff_initial_ms) {
    throw invalid_parameter("backoff_max_ms", "must be >= backoff_initial_ms");
  }
  if (max_idle_connections == 0 || max_idle_connections > 1024) {
    throw invalid_parameter("max_idle_connections", "must be 1..1024");
  }
  for (const std::string& url : redirect_origins) {
    if (!detail::http_origin(url)) {
      throw invalid_parameter("redirect_origins", "'" + url + "' is not an http(s)://host URL");
    }
  }
  if (aws_sigv4) {
    const AwsSigV4& s = *aws_sigv4;
    // Both go into "aws:amz:<region>:<service>", which libcurl splits at ':'.
    const auto label = [](const std::string& v) {
      return !v.empty() && v.size() <= 64 && std::all_of(v.begin(), v.end(), [](char c) {
        return std::islower(static_cast<unsigned char>(c)) ||
               std::isdigit(static_cast<unsigned char>(c)) || c == '-';
      });
    };
    if (!label(s.region)) {
      throw invalid_parameter("aws_sigv4.region", "'" + s.region + "' is not a region name");
    }
    if (!label(s.service)) {
      throw invalid_parameter("aws_sigv4.service", "'" + s.service + "' is not a service name");
    }
    // Secrets are never echoed, only named.
    if (s.access_key_id.empty() || has_control_character(s.access_key_id) ||
        s.access_key_id.find(':') != std::string::npos) {
      throw invalid_parameter("aws_sigv4.access_key_id",
                              "must be non-empty, without ':' or control characters");
    }
    if (s.secret_access_key.empty() || has_control_character(s.secret_access_key)) {
      throw invalid_parameter("aws_sigv4.secret_access_key",
                              "must be non-empty, without control characters");
    }
    if (has_control_character(s.session_token)) {
      throw invalid_parameter("aws_sigv4.session_token", "must not contain control characters");
    }
  }
}

struct HttpStore::Impl {
  UrlMap map;
  HttpOptions options;
  std::vector<std::string> origins;  ///< where redirects may lead (redirect_allowed)
  CURLSH* share = nullptr;
  std::array<std::mutex, CURL_LOCK_DATA_LAST> share_locks;
  std::mutex pool_mutex;
  std::vector<CURL*> pool;  // idle easy handles; each keeps its own keep-alive connections
  std::atomic<std::uint64_t> requests{0}, retries{0}, connections{0}, bytes{0};
  std::atomic<bool> suffix_refused{false};  ///< a server answered a suffix range without 206

  ~Impl() {
    for (CURL* h : pool) curl_easy_cleanup(h);
    if (share) curl_share_cleanup(share);
  }

  CURL* acquire() {
    {
      std::lock_guard lock(pool_mutex);
      if (!pool.empty()) {
        CURL* h = pool.back();  // LIFO: the most recently used handle has a live connection
        pool.pop_back();
        return h;
      }
    }
    CURL* h = curl_easy_init();
    if (!h) throw Error(ErrorCode::out_of_memory, "libcurl: curl_easy_init failed");
    return h;
  }

  void release(CURL* h) {
    std::lock_guard lock(pool_mutex);
    if (pool.size() < options.max_idle_connections) {
      pool.push_back(h);
    } else {
      curl_easy_cleanup(h);
    }
  }

  std::string url_of(std::string_view key) const {
    const std::string* best = &map.base;
    std::size_t best_len = 0;
    for (const auto& [prefix, url] : map.routes) {
      if (prefix.size() > best_len && prefix_matches(prefix, key)) {
        best = &url;
        best_len = prefix.size();
      }
    }
    return *best + "/" + detail::percent_encode_key(key);
  }

  /// Whether a redirect may lead to `target`: only to an origin (scheme, host, port) that the
  /// URL map or HttpOptions::redirect_origins names. libcurl's own redirect following can
  /// only restrict schemes, so a hostile server could otherwise send the loader to any host
  /// the machine reaches (a cloud metadata address, an intranet service) or downgrade https to
  /// http; redirects are therefore followed here, one hop at a time.
  bool redirect_allowed(const std::string& target) const {
    const std::optional<std::string> o = detail::http_origin(target);
    return o && std::find(origins.begin(), origins.end(), *o) != origins.end();
  }

  std::string origin_list() const {
    std::string s;
    for (const std::string& o : origins) s += (s.empty() ? "" : ", ") + o;
    return s;
  }

  /// One attempt (following allowed redirects); fills `why` for failures.
  Outcome attempt(CURL* h, const std::string& url, bool head, Attempt& a, ErrorCode& code,
                  std::string& why) {
    const Attempt request = a;
    std::string target = url;
    for (int hop = 0;; ++hop) {
      const Outcome o = attempt_one(h, target, head, a, code, why);
      if (o != Outcome::redirect) return o;
      char* location = nullptr;
      curl_easy_getinfo(h, CURLINFO_REDIRECT_URL, &location);
      const std::string next = location != nullptr ? location : "";
      if (hop == kMaxRedirects) {
        code = ErrorCode::io;
        why = "more than " + std::to_string(kMaxRedirects) + " redirects (last to '" + next + "')";
        return Outcome::fail;
      }
      if (!redirect_allowed(next)) {
        code = ErrorCode::invalid_argument;
        why = "redirect (HTTP " + std::to_string(a.status) + ") to '" + next +
              "' refused: it leaves the allowed origins (" + origin_list() + ")";
        return Outcome::fail;
      }
      target = next;
      a = request;  // forget what the redirect answer carried
    }
  }

  /// Sets the SigV4 options on `h` when the store signs; returns the extra headers, which must
  /// outlive the request (nullptr when unsigned).
  curl_slist* sign(CURL* h) const {
    if (!options.aws_sigv4) return nullptr;
    const AwsSigV4& s = *options.aws_sigv4;
    const std::string provider = "aws:amz:" + s.region + ":" + s.service;
    curl_easy_setopt(h, CURLOPT_AWS_SIGV4, provider.c_str());  // libcurl copies strings
    curl_easy_setopt(h, CURLOPT_USERNAME, s.access_key_id.c_str());
    curl_easy_setopt(h, CURLOPT_PASSWORD, s.secret_access_key.c_str());
    curl_slist* list = curl_slist_append(nullptr, kEmptyPayloadSha256);
    if (list != nullptr && !s.session_token.empty()) {
      const std::string token = "x-amz-security-token: " + s.session_token;
      curl_slist* more = curl_slist_append(list, token.c_str());
      if (more == nullptr) curl_slist_free_all(list);
      list = more;
    }
    if (list == nullptr) throw Error(ErrorCode::out_of_memory, "libcurl: curl_slist_append failed");
    curl_easy_setopt(h, CURLOPT_HTTPHEADER, list);
    return list;
  }

  /// One request, without following redirects.
  Outcome attempt_one(CURL* h, const std::string& url, bool head, Attempt& a, ErrorCode& code,
                      std::string& why) {
    curl_easy_reset(h);  // keeps the handle's connections, drops the previous request's options
    curl_easy_setopt(h, CURLOPT_URL, url.c_str());
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(h, CURLOPT_SHARE, share);
    curl_easy_setopt(h, CURLOPT_PROTOCOLS_STR, "http,https");
    // Redirects are followed by attempt(), which checks each target's origin first; the
    // protocol list stays as a second line of defence.
    curl_easy_setopt(h, CURLOPT_FOLLOWLOCATION, 0L);
    curl_easy_setopt(h, CURLOPT_REDIR_PROTOCOLS_STR, "http,https");
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT_MS, long(options.connect_timeout_ms));
    curl_easy_setopt(h, CURLOPT_TIMEOUT_MS, long(options.total_timeout_ms));
    if (options.low_speed_bytes != 0) {
      curl_easy_setopt(h, CURLOPT_LOW_SPEED_LIMIT, long(options.low_speed_bytes));
      curl_easy_setopt(h, CURLOPT_LOW_SPEED_TIME, long(options.low_speed_time_s));
    }
    curl_easy_setopt(h, CURLOPT_MAXCONNECTS, long(options.max_idle_connections));
    curl_easy_setopt(h, CURLOPT_TCP_KEEPALIVE, 1L);
    curl_easy_setopt(h, CURLOPT_HEADERFUNCTION, detail::on_header);
    curl_easy_setopt(h, CURLOPT_HEADERDATA, &a);
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, detail::on_body);
    curl_easy_setopt(h, CURLOPT_WRITEDATA, &a);
    if (head) curl_easy_setopt(h, CURLOPT_NOBODY, 1L);
    std::string range;
    if (a.ranged && a.suffix) {
      range = "-" + std::to_string(a.want);
      curl_easy_setopt(h, CURLOPT_RANGE, range.c_str());
    } else if (a.ranged) {
      range = std::to_string(a.offset) + "-" + std::to_string(a.offset + a.want - 1);
      curl_easy_setopt(h, CURLOPT_RANGE, range.c_str());
    }
    char curl_error[CURL_ERROR_SIZE] = {};
    curl_easy_setopt(h, CURLOPT_ERRORBUFFER, curl_error);
    // Signed anew for each hop and attempt: the signature covers the URL and the time.
    const std::unique_ptr<curl_slist, decltype(&curl_slist_free_all)> headers(sign(h),
                                                                              curl_slist_free_all);

    const CURLcode rc = curl_easy_perform(h);
    ++requests;
    long connects = 0;
    if (curl_easy_getinfo(h, CURLINFO_NUM_CONNECTS, &connects) == CURLE_OK && connects > 0) {
      connections += std::uint64_t(connects);
    }
    long status = 0;
    curl_easy_getinfo(h, CURLINFO_RESPONSE_CODE, &status);
    if (status != 0) a.status = status;

    if (a.too_large) {
      code = ErrorCode::out_of_range;
      why = "object exceeds the limit of " + std::to_string(a.max_bytes) + " bytes";
      return Outcome::fail;
    }
    if (!a.bad_answer.empty()) {
      code = ErrorCode::io;
      why = a.bad_answer;
      return Outcome::fail;
    }
    if (a.suffix_refused) return Outcome::no_suffix;
    if (a.complete_early) return Outcome::done;
    if (rc == CURLE_OK && a.status >= 300 && a.status < 400) {
      char* location = nullptr;
      if (curl_easy_getinfo(h, CURLINFO_REDIRECT_URL, &location) == CURLE_OK &&
          location != nullptr) {
        return Outcome::redirect;
      }
    }
    if (rc != CURLE_OK) {
      const char* text = curl_error[0] ? curl_error : curl_easy_strerror(rc);
      code = rc == CURLE_PARTIAL_FILE ? ErrorCode::truncated : ErrorCode::io;
      why = std::string(rc == CURLE_PARTIAL_FILE ? "truncated body: " : "") + text;
      return transient(rc) ? Outcome::retry : Outcome::fail;
    }
    if (a.status == 404 && a.s3_code() == "NoSuchBucket") {
      code = ErrorCode::io;
      why = a.status_text();
      return Outcome::fail;
    }
    if (a.status == 404 || a.status == 410) {
      code = ErrorCode::io;
      why = "not found (HTTP " + std::to_string(a.status) + ")";
      return Outcome::absent;
    }
    if (a.suffix && (a.status == 400 || a.status == 416 || a.status == 501)) {
      return Outcome::no_suffix;  // suffix ranges unsupported (or an empty object): fall back
    }
    if (a.status == 416) {
      code = ErrorCode::truncated;
      why = "range of " + std::to_string(a.want) + " bytes starts past the end (HTTP 416)";
      return Outcome::fail;
    }
    if (a.status == 408 || a.status == 429 || (a.status >= 500 && a.status < 600)) {
      code = ErrorCode::io;
      why = a.status_text();
      return Outcome::retry;
    }
    if (!a.ok_status()) {
      code = ErrorCode::io;
      why = a.status_text();
      return Outcome::fail;
    }
    if (!head && a.content_length && *a.content_length != a.received) {
      code = ErrorCode::truncated;
      why = "truncated body: " + std::to_string(a.received) + " of " +
            std::to_string(*a.content_length) + " announced bytes";
      return Outcome::retry;
    }
    if (a.ranged && a.suffix) return check_suffix(a, code, why);
    if (a.ranged) return check_range(a, code, why);
    return Outcome::done;
  }

  static Outcome check_suffix(Attempt& a, ErrorCode& code, std::string& why) {
    if (a.status != 206) return Outcome::no_suffix;
    const auto cr = parse_content_range(a.content_range);
    if (!cr || !cr->total || cr->last + 1 != *cr->total || cr->first > cr->last) {
      code = ErrorCode::io;
      why = "206 answer with Content-Range '" + a.content_range + "' for the last " +
            std::to_string(a.want) + " bytes";
      return Outcome::fail;
    }
    if (*cr->total < a.want) {
      code = ErrorCode::truncated;
      why = "object of " + std::to_string(*cr->total) + " bytes is shorter than the " +
            std::to_string(a.want) + " bytes wanted from its end";
      return Outcome::fail;
    }
    if (cr->first != *cr->total - a.want || a.received != a.want) {
      code = ErrorCode::io;
      why = "206 answer with Content-Range '" + a.content_range + "' (" +
            std::to_string(a.received) + " bytes) for the last " + std::to_string(a.want) +
            " bytes";
      return Outcome::fail;
    }
    a.object_size = *cr->total;
    return Outcome::done;
  }

  static Outcome check_range(const Attempt& a, ErrorCode& code, std::string& why) {
    if (a.status == 206) {
      const auto cr = parse_content_range(a.content_range);  // TOTAL may be '*'
      if (!cr || cr->first != a.offset || cr->last < cr->first ||
          cr->last > a.offset + a.want - 1) {
        code = ErrorCode::io;
        why = "206 answer with Content-Range '" + a.content_range + "' for bytes " +
              std::to_string(a.offset) + "-" + std::to_string(a.offset + a.want - 1);
        return Outcome::fail;
      }
      if (cr->last - cr->first + 1 != a.received || a.received < a.want) {
        code = ErrorCode::truncated;
        why = "object ends after " + std::to_string(a.received) + " of " + std::to_string(a.want) +
              " requested bytes";
        return Outcome::fail;
      }
      return Outcome::done;
    }
    // A complete 200 body that never reached offset + want: the object is shorter.
    code = ErrorCode::truncated;
    why = "object of " + std::to_string(a.received) + " bytes ends before the range of " +
          std::to_string(a.want) + " bytes";
    return Outcome::fail;
  }

  /// Runs attempts with backoff. Returns false for absence; throws for failures.
  bool run(std::string_view key, bool head, Attempt& proto, std::vector<std::byte>* whole) {
    const std::string url = url_of(key);
    CURL* h = acquire();
    struct Release {
      Impl* self;
      CURL* h;
      ~Release() { self->release(h); }
    } release_guard{this, h};
    std::uint32_t delay = options.backoff_initial_ms;
    for (std::uint32_t attempt_no = 0;; ++attempt_no) {
      Attempt a = proto;
      if (whole) whole->clear();
      ErrorCode code = ErrorCode::io;
      std::string why;
      const Outcome o = attempt(h, url, head, a, code, why);
      if (o == Outcome::done) {
        bytes += a.kept;
        proto = a;
        return true;
      }
      if (o == Outcome::absent) return false;
      if (o == Outcome::no_suffix) {
        proto = a;
        proto.suffix_refused = true;
        return true;
      }
      if (o == Outcome::retry && attempt_no < options.retries) {
        ++retries;
        // A server that says when to come back (503 or 429 with Retry-After) is waited for, up
        // to the backoff cap: retrying sooner would only meet the same answer.
        std::uint64_t wait = delay;
        if (a.retry_after_ms) wait = std::max<std::uint64_t>(wait, *a.retry_after_ms);
        wait = std::min<std::uint64_t>(wait, std::max(delay, options.backoff_max_ms));
        std::this_thread::sleep_for(std::chrono::milliseconds(wait));
        delay = std::min(options.backoff_max_ms, delay * 2);
        continue;
      }
      const std::string attempts =
          " (" + std::to_string(attempt_no + 1) + (attempt_no == 0 ? " attempt)" : " attempts)");
      if (proto.ranged) throw file_error(code, url, proto.offset, why + attempts);
      throw Error(code, url + ": " + why + attempts);
    }
  }
};

HttpStore::HttpStore(UrlMap map, HttpOptions options) : impl_(std::make_unique<Impl>()) {
  options.validate();
  check_url(map.base);
  map.base = trim_slashes(map.base);
  for (auto& [prefix, url] : map.routes) {
    check_store_key(prefix);
    check_url(url);
    url = trim_slashes(url);
  }
  global_init();
  // Redirects may lead to the hosts the caller named, and nowhere else.
  auto allow = [&](const std::string& url) {
    const std::optional<std::string> o = detail::http_origin(url);
    if (!o) throw invalid_parameter("url_map", "'" + url + "' has no http(s) origin");
    if (std::find(impl_->origins.begin(), impl_->origins.end(), *o) == impl_->origins.end()) {
      impl_->origins.push_back(*o);
    }
  };
  allow(map.base);
  for (const auto& [prefix, url] : map.routes) allow(url);
  for (const std::string& url : options.redirect_origins) allow(url);
  impl_->map = std::move(map);
  impl_->options = options;
  impl_->share = curl_share_init();
  if (!impl_->share) throw Error(ErrorCode::out_of_memory, "libcurl: curl_share_init failed");
  // Connections are not shared between handles: libcurl does not support a shared connection
  // cache used by concurrent threads. Each pooled handle keeps its own keep-alive connections;
  // DNS answers and TLS sessions are shared.
  curl_share_setopt(
      impl_->share, CURLSHOPT_LOCKFUNC,
      +[](CURL*, curl_lock_data data, curl_lock_access, void* user) {
        static_cast<Impl*>(user)->share_locks[std::size_t(data)].lock();
      });
  curl_share_setopt(
      impl_->share, CURLSHOPT_UNLOCKFUNC, +[](CURL*, curl_lock_data data, void* user) {
        static_cast<Impl*>(user)->share_locks[std::size_t(data)].unlock();
      });
  curl_share_setopt(impl_->share, CURLSHOPT_USERDATA, impl_.get());
  curl_share_setopt(impl_->share, CURLSHOPT_SHARE, CURL_LOCK_DATA_DNS);
  curl_share_setopt(impl_->share, CURLSHOPT_SHARE, CURL_LOCK_DATA_SSL_SESSION);
}

HttpStore::~HttpStore() = default;

std::optional<std::vector<std::byte>> HttpStore::get(std::string_view key,
                                                     std::uint64_t max_bytes) const {
  check_store_key(key);
  std::vector<std::byte> body;
  Attempt a;
  a.max_bytes = max_bytes;
  a.whole = &body;
  if (!impl_->run(key, false, a, &body)) return std::nullopt;
  return body;
}

bool HttpStore::read_range_if_present(std::string_view key, std::uint64_t offset,
                                      std::span<std::byte> out) const {
  check_store_key(key);
  if (out.empty()) return true;
  if (offset > std::numeric_limits<std::uint64_t>::max() - out.size()) {
    throw invalid_parameter("offset", "offset + size overflows");
  }
  Attempt a;
  a.ranged = true;
  a.offset = offset;
  a.want = out.size();
  a.out = out;
  return impl_->run(key, false, a, nullptr);
}

void HttpStore::read_range(std::string_view key, std::uint64_t offset,
                           std::span<std::byte> out) const {
  if (!read_range_if_present(key, offset, out)) {
    throw file_error(ErrorCode::io, location(key), offset, "not found (HTTP 404)");
  }
}

std::optional<std::vector<std::byte>> HttpStore::get_range_if_present(std::string_view key,
                                                                      std::uint64_t offset,
                                                                      std::uint64_t size) const {
  check_store_key(key);
  std::vector<std::byte> out(static_cast<std::size_t>(size));
  if (!read_range_if_present(key, offset, out)) return std::nullopt;
  if (size == 0 && !this->size(key)) return std::nullopt;
  return out;
}

std::optional<ObjectTail> HttpStore::get_suffix(std::string_view key, std::uint64_t size) const {
  check_store_key(key);
  if (size > 0 && !impl_->suffix_refused.load(std::memory_order_relaxed)) {
    ObjectTail tail{std::vector<std::byte>(static_cast<std::size_t>(size)), 0};
    Attempt a;
    a.ranged = true;
    a.suffix = true;
    a.want = size;
    a.out = tail.bytes;
    if (!impl_->run(key, false, a, nullptr)) return std::nullopt;
    if (!a.suffix_refused) {
      tail.object_size = a.object_size;
      return tail;
    }
    // Remembered: every later suffix read of this store goes straight to the fallback.
    impl_->suffix_refused.store(true, std::memory_order_relaxed);
  }
  // Fallback for servers without suffix ranges: the size from HEAD, then a first-last range.
  const std::optional<std::uint64_t> n = this->size(key);
  if (!n) return std::nullopt;
  if (*n < size) {
    throw file_error(ErrorCode::truncated, location(key), 0,
                     "object of " + std::to_string(*n) + " bytes is shorter than the " +
                         std::to_string(size) + " bytes wanted from its end");
  }
  ObjectTail tail{std::vector<std::byte>(static_cast<std::size_t>(size)), *n};
  read_range(key, *n - size, tail.bytes);
  return tail;
}

std::vector<std::byte> HttpStore::get_range(std::string_view key, std::uint64_t offset,
                                            std::uint64_t size) const {
  check_store_key(key);
  // Allocation follows the caller's request, as for a local file after its size check; the
  // caller bounds `size` (brick store index entries are validated first).
  std::vector<std::byte> out(static_cast<std::size_t>(size));
  read_range(key, offset, out);
  return out;
}

std::optional<std::uint64_t> HttpStore::size(std::string_view key) const {
  check_store_key(key);
  Attempt a;
  a.max_bytes = std::numeric_limits<std::uint64_t>::max();
  if (!impl_->run(key, true, a, nullptr)) return std::nullopt;
  if (!a.content_length) {
    throw Error(ErrorCode::io, location(key) + ": HEAD answer without Content-Length");
  }
  return *a.content_length;
}

std::string HttpStore::location(std::string_view key) const {
  return impl_->url_of(key);
}

const UrlMap& HttpStore::url_map() const noexcept {
  return impl_->map;
}

const HttpOptions& HttpStore::options() const noexcept {
  return impl_->options;
}

HttpStats HttpStore::stats() const {
  HttpStats s;
  s.requests = impl_->requests.load();
  s.retries = impl_->retries.load();
  s.connections = impl_->connections.load();
  s.bytes = impl_->bytes.load();
  return s;
}

std::shared_ptr<HttpStore> open_http_store(std::string_view url_map_spec, HttpOptions options) {
  return std::make_shared<HttpStore>(parse_url_map(url_map_spec), options);
}

}  // namespace resoct
