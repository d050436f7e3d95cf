#pragma once
// One HTTP request attempt of HttpStore (internal): what the caller wants, what arrived, and the
// libcurl callbacks that fill it in and judge the answer as it streams (a range answered with
// the whole object, a suffix range a server misreads, an oversized body, an S3 error document).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <curl/curl.h>

#include "io/http/s3_error_code.hpp"

namespace resoct::detail {

/// An unsigned decimal number with surrounding blanks, or nullopt.
std::optional<std::uint64_t> parse_u64(std::string_view s);

/// State of one attempt, shared with libcurl's callbacks.
struct Attempt {
  // What the caller wants.
  bool ranged = false;
  bool suffix = false;                      // ranged: the last `want` bytes ("bytes=-want")
  std::uint64_t offset = 0;                 // ranged: first byte wanted
  std::uint64_t want = 0;                   // ranged: bytes wanted
  std::uint64_t max_bytes = 0;              // whole object: limit
  std::span<std::byte> out;                 // ranged: destination
  std::vector<std::byte>* whole = nullptr;  // whole object: destination
  // What arrived.
  long status = 0;
  std::optional<std::uint64_t> content_length;
  std::string content_range;
  std::uint64_t received = 0;  // body bytes of the final response
  std::uint64_t kept = 0;
  bool too_large = false;
  bool complete_early = false;    // a 200 answer to a range request: stopped once `want` arrived
  bool suffix_refused = false;    // a suffix request answered otherwise than with 206: fall back
  std::uint64_t object_size = 0;  // suffix: the total from Content-Range
  std::string bad_answer;         // set when the server's answer contradicts the request
  std::string error_body;         // the first bytes of an error answer (an S3 <Error> document)
  std::string error_code;         // an x-amz-error-code header (S3 stores; HEAD answers too)
  std::optional<std::uint64_t> retry_after_ms;  // a Retry-After header (delay or date), in ms

  bool ok_status() const { return status >= 200 && status < 300; }

  /// The S3 error code of the answer: the header's, else the body's ("" for none).
  std::string s3_code() const {
    return error_code.empty() ? detail::s3_error_code(error_body) : error_code;
  }
  /// "HTTP 403", with the S3 error code and advice when the answer has one:
  /// "HTTP 403 SignatureDoesNotMatch: the secret access key is wrong".
  std::string status_text() const {
    std::string text = "HTTP " + std::to_string(status);
    const std::string code = s3_code();
    if (code.empty()) return text;
    text += " " + code;
    const std::string_view advice = detail::s3_error_advice(code);
    if (!advice.empty()) text += ": " + std::string(advice);
    return text;
  }
};

/// The wait a Retry-After value asks for, in ms: delta-seconds ("120") or an HTTP-date (its
/// distance from `now_s`, 0 when past); nullopt when it is neither.
std::optional<std::uint64_t> parse_retry_after(std::string_view value, std::int64_t now_s);

/// libcurl's CURLOPT_HEADERFUNCTION / CURLOPT_WRITEFUNCTION; `user` is the Attempt.
std::size_t on_header(char* data, std::size_t size, std::size_t n, void* user);
std::size_t on_body(char* data, std::size_t size, std::size_t n, void* user);

/// "bytes FIRST-LAST/TOTAL" of a 206 answer, or nullopt (TOTAL: nullopt when '*').
struct ContentRange {
  std::uint64_t first = 0, last = 0;
  std::optional<std::uint64_t> total;
};
std::optional<ContentRange> parse_content_range(std::string_view cr);

/// Failures worth another attempt: timeouts, refused or reset connections, truncated bodies.
bool transient(CURLcode c);

}  // namespace resoct::detail
