// "s3://bucket/key" specs and the URL of a bucket (path-style or virtual-hosted addressing).
#include <algorithm>
#include <cctype>

#include "resoct/base/error.hpp"
#include "resoct/io/http/s3_store.hpp"

namespace resoct {

namespace {

constexpr std::string_view kScheme = "s3://";

Error bad_spec(std::string_view spec, const std::string& why) {
  // Appended piecewise: g++ 12 warns (-Wrestrict, falsely) about the chained operator+.
  std::string text = "'";
  text.append(spec).append("': ").append(why);
  return invalid_parameter("spec", text);
}

bool is_ipv4_address(std::string_view s) {
  int dots = 0;
  for (char c : s) {
    if (c == '.') {
      ++dots;
    } else if (!std::isdigit(static_cast<unsigned char>(c))) {
      return false;
    }
  }
  return dots == 3;
}

/// S3's bucket naming rules (general purpose buckets): 3-63 characters of a-z 0-9 . -, a letter
/// or digit at both ends, no "..", not formatted as an IP address. They also keep a bucket name
/// a valid host name label sequence and a single URL path component.
std::string bucket_name_problem(std::string_view b) {
  if (b.size() < 3 || b.size() > 63) return "bucket name must have 3 to 63 characters";
  const bool chars_ok = std::all_of(b.begin(), b.end(), [](char c) {
    return std::islower(static_cast<unsigned char>(c)) ||
           std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-';
  });
  if (!chars_ok) return "bucket name may only contain a-z, 0-9, '.' and '-'";
  const auto alnum = [](char c) {
    return std::islower(static_cast<unsigned char>(c)) ||
           std::isdigit(static_cast<unsigned char>(c));
  };
  if (!alnum(b.front()) || !alnum(b.back())) {
    return "bucket name must start and end with a letter or digit";
  }
  if (b.find("..") != std::string_view::npos) return "bucket name must not contain '..'";
  if (is_ipv4_address(b)) return "bucket name must not be an IP address";
  return {};
}

}  // namespace

bool is_s3_url(std::string_view s) noexcept {
  if (s.size() < kScheme.size()) return false;
  for (std::size_t i = 0; i < kScheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[i])) != kScheme[i]) return false;
  }
  return true;
}

S3Path parse_s3_url(std::string_view spec) {
  if (!is_s3_url(spec)) throw bad_spec(spec, "not an s3://bucket/key spec");
  if (spec.find_first_of("?#") != std::string_view::npos) {
    throw bad_spec(spec, "a query or fragment is unsupported");
  }
  std::string_view rest = spec.substr(kScheme.size());
  while (rest.ends_with('/')) rest.remove_suffix(1);
  const std::size_t slash = rest.find('/');
  S3Path path;
  path.bucket = std::string(rest.substr(0, slash));
  if (path.bucket.empty()) throw bad_spec(spec, "no bucket (expected s3://bucket/key)");
  if (const std::string why = bucket_name_problem(path.bucket); !why.empty()) {
    throw bad_spec(spec, why);
  }
  if (slash != std::string_view::npos) {
    path.key = std::string(rest.substr(slash + 1));
    try {
      check_store_key(path.key);
    } catch (const Error&) {
      throw bad_spec(
          spec, "key '" + path.key + "' is not a valid store key (empty, '.' or '..' components)");
    }
  }
  return path;
}

std::string s3_bucket_url(const S3Config& config, std::string_view bucket) {
  if (!config.endpoint.empty()) return config.endpoint + "/" + std::string(bucket);
  if (bucket.find('.') != std::string_view::npos) {
    return "https://s3." + config.region + ".amazonaws.com/" + std::string(bucket);
  }
  return "https://" + std::string(bucket) + ".s3." + config.region + ".amazonaws.com";
}

}  // namespace resoct
