#pragma once
// The origin (scheme, host, port) of an http(s) URL, which decides where an HttpStore lets a
// redirect lead (internal).

#include <optional>
#include <string>
#include <string_view>

namespace resoct::detail {

/// "scheme://host:port" of `url`, scheme and host lowercased, the port explicit (80 / 443 when
/// the URL gives none), parsed by libcurl's own URL parser so that the origin compared is the
/// one libcurl connects to (user info such as "http://a@b/" cannot disguise host b). nullopt
/// when the URL does not parse or its scheme is not http or https.
std::optional<std::string> http_origin(std::string_view url);

}  // namespace resoct::detail
