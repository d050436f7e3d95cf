#include "io/http/http_attempt.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <ctime>

#include <curl/curl.h>

namespace resoct::detail {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

/// Bytes of an error answer kept: an S3 <Error> document names its code near the start.
constexpr std::size_t kErrorBodyBytes = 4096;

}  // namespace

std::optional<std::uint64_t> parse_u64(std::string_view s) {
  s = trim(s);
  std::uint64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::size_t on_header(char* data, std::size_t size, std::size_t n, void* user) {
  auto& a = *static_cast<Attempt*>(user);
  const std::size_t len = size * n;
  std::string_view line(data, len);
  if (line.starts_with("HTTP/")) {
    // A new response (after a redirect or "100 Continue"): forget the previous headers.
    a.content_length.reset();
    a.content_range.clear();
    a.error_code.clear();
    a.retry_after_ms.reset();
    const std::size_t sp = line.find(' ');
    a.status = 0;
    if (sp != std::string_view::npos) {
      std::from_chars(line.data() + sp + 1, line.data() + std::min(len, sp + 4), a.status);
    }
    return len;
  }
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos) return len;
  std::string name(line.substr(0, colon));
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  const std::string_view value = line.substr(colon + 1);
  if (name == "content-length") {
    a.content_length = parse_u64(value);
    // Refuse an oversized object before its first byte arrives.
    if (!a.ranged && a.ok_status() && a.content_length && *a.content_length > a.max_bytes) {
      a.too_large = true;
      return 0;
    }
  } else if (name == "content-range") {
    a.content_range = std::string(trim(value));
  } else if (name == "retry-after") {
    a.retry_after_ms = parse_retry_after(value, std::int64_t(std::time(nullptr)));
  } else if (name == "x-amz-error-code") {
    a.error_code = detail::s3_error_code("<Error><Code>" + std::string(trim(value)) + "</Code>");
  }
  return len;
}

std::optional<std::uint64_t> parse_retry_after(std::string_view value, std::int64_t now_s) {
  // Seconds beyond a day are as good as "not soon": the caller caps the wait anyway, and the cap
  // keeps the product below overflow.
  constexpr std::uint64_t kMaxSeconds = 86400;
  if (const std::optional<std::uint64_t> s = parse_u64(value)) {
    return std::min(*s, kMaxSeconds) * 1000u;
  }
  const std::string text(trim(value));
  const std::int64_t when = std::int64_t(curl_getdate(text.c_str(), nullptr));
  if (when < 0) return std::nullopt;
  return std::uint64_t(std::clamp<std::int64_t>(when - now_s, 0, std::int64_t(kMaxSeconds))) *
         1000u;
}

std::optional<ContentRange> parse_content_range(std::string_view cr) {
  if (!cr.starts_with("bytes ")) return std::nullopt;
  cr.remove_prefix(6);
  const std::size_t dash = cr.find('-'), slash = cr.find('/');
  if (dash == std::string_view::npos || slash == std::string_view::npos || dash > slash) {
    return std::nullopt;
  }
  const auto first = parse_u64(cr.substr(0, dash));
  const auto last = parse_u64(cr.substr(dash + 1, slash - dash - 1));
  if (!first || !last) return std::nullopt;
  return ContentRange{*first, *last, parse_u64(cr.substr(slash + 1))};
}

namespace {

/// Whether a 206 answer to "bytes=-want" is the object's tail. Some servers misread a suffix
/// range (s3rver parses "bytes=-132" as bytes 0-132): their answer is a refusal, not data.
bool answers_suffix(const Attempt& a) {
  const auto cr = parse_content_range(a.content_range);
  return cr && cr->total && cr->last + 1 == *cr->total &&
         cr->first == *cr->total - std::min(a.want, *cr->total);
}

}  // namespace

std::size_t on_body(char* data, std::size_t size, std::size_t n, void* user) {
  auto& a = *static_cast<Attempt*>(user);
  const std::size_t len = size * n;
  const auto* bytes = reinterpret_cast<const std::byte*>(data);
  const std::uint64_t at = a.received;
  a.received += len;
  if (!a.ok_status()) {
    // An error page: only the status matters, and an S3 error code if the page has one.
    a.error_body.append(data, std::min<std::size_t>(len, kErrorBodyBytes - a.error_body.size()));
    return len;
  }
  if (!a.ranged) {
    if (a.received > a.max_bytes) {
      a.too_large = true;
      return 0;
    }
    a.whole->insert(a.whole->end(), bytes, bytes + len);
    a.kept = a.received;
    return len;
  }
  if (a.status == 206) {
    if (a.suffix && at == 0 && !answers_suffix(a)) {
      a.suffix_refused = true;  // the caller falls back to the size and a first-last range
      return 0;
    }
    if (a.received > a.want) {
      a.bad_answer = "206 answer longer than the " + std::to_string(a.want) + " bytes requested";
      return 0;
    }
    std::memcpy(a.out.data() + at, bytes, len);
    a.kept = a.received;
    return len;
  }
  if (a.suffix) {
    // 200 to a suffix request: the server ignores suffix ranges. Streaming the whole object to
    // keep its end would cost what the range was meant to save; the caller asks for the size
    // and then a first-last range instead.
    a.suffix_refused = true;
    return 0;
  }
  // 200 to a range request: the whole object streams in; keep only [offset, offset + want).
  const std::uint64_t lo = std::max(at, a.offset);
  const std::uint64_t hi = std::min<std::uint64_t>(a.received, a.offset + a.want);
  if (lo < hi) {
    std::memcpy(a.out.data() + (lo - a.offset), bytes + (lo - at), std::size_t(hi - lo));
    a.kept += hi - lo;
  }
  if (a.kept == a.want) {
    a.complete_early = true;
    return 0;  // abort: the rest of the object is not needed
  }
  return len;
}

bool transient(CURLcode c) {
  switch (c) {
    case CURLE_OPERATION_TIMEDOUT:
    case CURLE_COULDNT_CONNECT:
    case CURLE_RECV_ERROR:
    case CURLE_SEND_ERROR:
    case CURLE_GOT_NOTHING:
    case CURLE_PARTIAL_FILE:
    case CURLE_HTTP2:
    case CURLE_HTTP2_STREAM:
    case CURLE_SSL_CONNECT_ERROR: return true;
    default: return false;
  }
}

}  // namespace resoct::detail
