#include "io/http/http_origin.hpp"

#include <algorithm>
#include <cctype>
#include <memory>

#include <curl/curl.h>

namespace resoct::detail {

namespace {

struct UrlDeleter {
  void operator()(CURLU* u) const noexcept { curl_url_cleanup(u); }
};

std::optional<std::string> part(CURLU* u, CURLUPart which, unsigned flags) {
  char* text = nullptr;
  if (curl_url_get(u, which, &text, flags) != CURLUE_OK || text == nullptr) return std::nullopt;
  std::string s(text);
  curl_free(text);
  std::transform(s.begin(), s.end(), s.begin(),
                 [](char c) { return char(std::tolower(static_cast<unsigned char>(c))); });
  return s;
}

}  // namespace

std::optional<std::string> http_origin(std::string_view url) {
  const std::unique_ptr<CURLU, UrlDeleter> u(curl_url());
  if (!u) return std::nullopt;
  const std::string text(url);
  // Schemes this libcurl build does not support still parse, so that they are refused below by
  // name rather than by accident.
  if (curl_url_set(u.get(), CURLUPART_URL, text.c_str(), CURLU_NON_SUPPORT_SCHEME) != CURLUE_OK) {
    return std::nullopt;
  }
  const auto scheme = part(u.get(), CURLUPART_SCHEME, 0);
  if (!scheme || (*scheme != "http" && *scheme != "https")) return std::nullopt;
  const auto host = part(u.get(), CURLUPART_HOST, 0);
  const auto port = part(u.get(), CURLUPART_PORT, CURLU_DEFAULT_PORT);
  if (!host || host->empty() || !port) return std::nullopt;
  return *scheme + "://" + *host + ":" + *port;
}

}  // namespace resoct::detail
