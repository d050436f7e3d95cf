#include "io/http/s3_error_code.hpp"

#include <algorithm>
#include <cctype>

namespace resoct::detail {

std::string s3_error_code(std::string_view body) {
  if (body.find("<Error>") == std::string_view::npos) return {};
  constexpr std::string_view open = "<Code>", close = "</Code>";
  const std::size_t start = body.find(open);
  if (start == std::string_view::npos) return {};
  const std::size_t end = body.find(close, start + open.size());
  if (end == std::string_view::npos) return {};
  std::string code(body.substr(start + open.size(), end - start - open.size()));
  // A code is an identifier; anything else is not echoed into messages.
  const bool plain =
      !code.empty() && code.size() <= 64 && std::all_of(code.begin(), code.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_';
      });
  return plain ? code : std::string();
}

std::string_view s3_error_advice(std::string_view code) {
  if (code == "SignatureDoesNotMatch") return "the secret access key is wrong";
  if (code == "InvalidAccessKeyId") return "the access key id is unknown to the store";
  if (code == "InvalidToken" || code == "ExpiredToken") {
    return "the session token is invalid or expired";
  }
  if (code == "AccessDenied") return "the credentials (or anonymous access) may not read this";
  if (code == "NoSuchBucket") return "the bucket does not exist";
  if (code == "PermanentRedirect" || code == "AuthorizationHeaderMalformed") {
    return "the bucket is in another region: set AWS_REGION";
  }
  return {};
}

}  // namespace resoct::detail
