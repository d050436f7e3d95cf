#pragma once
// Store keys in URLs (internal): the HTTP store appends keys to its base URL, the S3 store puts a
// key prefix into the bucket's URL, and both must encode alike so that a key names one object.

#include <string>
#include <string_view>

namespace resoct::detail {

/// `key` with its bytes outside [A-Za-z0-9._~/-] percent-encoded (uppercase hex). These are the
/// characters AWS SigV4 leaves unencoded in a canonical URI, so the URL libcurl signs is the URL
/// S3 checks.
std::string percent_encode_key(std::string_view key);

}  // namespace resoct::detail
