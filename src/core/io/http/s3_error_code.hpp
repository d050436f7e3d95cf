#pragma once
// The error code of an S3 error answer (internal). S3 and compatible stores explain a failure
// in an XML body "<Error><Code>NoSuchBucket</Code>...", and some also in an x-amz-error-code
// header (HEAD answers have no body). The code tells a missing bucket from a missing key (both
// HTTP 404) and a bad secret from a forbidden object (both HTTP 403).

#include <string>
#include <string_view>

namespace resoct::detail {

/// The text of the first <Code> element of an <Error> document, or "" when `body` is none
/// (a plain HTTP server's error page). Only the first bytes of a body are kept by the caller.
std::string s3_error_code(std::string_view body);

/// What to do about `code`, for messages ("" for codes without advice).
std::string_view s3_error_advice(std::string_view code);

}  // namespace resoct::detail
