// Where an S3 store is and who reads it: S3Options completed from the environment and the shared
// credentials file, in the order the AWS CLI uses, so that a shell set up for `aws s3` works.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>

#include "io/http/http_origin.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/http/s3_store.hpp"

namespace resoct {

namespace {

/// A variable's value; an empty value counts as unset, as for the AWS CLI.
std::optional<std::string> lookup(const EnvironmentLookup& env, const std::string& name) {
  std::optional<std::string> v = env(name);
  if (v && v->empty()) v.reset();
  return v;
}

bool truthy(const std::optional<std::string>& v) {
  if (!v) return false;
  std::string s = *v;
  std::transform(s.begin(), s.end(), s.begin(),
                 [](char c) { return char(std::tolower(static_cast<unsigned char>(c))); });
  return s == "1" || s == "true" || s == "yes";
}

std::string trimmed(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return std::string(s);
}

/// "http(s)://host[:port][/path]" without a trailing '/'; throws naming `field`.
std::string checked_endpoint(std::string_view endpoint, const std::string& field) {
  std::string e(endpoint);
  while (!e.empty() && e.back() == '/') e.pop_back();
  const bool plain = std::none_of(e.begin(), e.end(), [](char c) {
    return static_cast<unsigned char>(c) <= 0x20 || c == 0x7F || c == '?' || c == '#';
  });
  if (!plain || !is_http_url(e) || !detail::http_origin(e)) {
    throw invalid_parameter(
        field, "'" + std::string(endpoint) + "' is not an http(s)://host[:port] endpoint URL");
  }
  return e;
}

/// Key id and secret, both or neither; `what` names their origin in messages.
std::optional<AwsSigV4> pair(const std::optional<std::string>& id,
                             const std::optional<std::string>& secret, const std::string& id_name,
                             const std::string& secret_name) {
  if (!id && !secret) return std::nullopt;
  if (!id) throw invalid_parameter(id_name, "not set, but " + secret_name + " is");
  if (!secret) throw invalid_parameter(secret_name, "not set, but " + id_name + " is");
  AwsSigV4 s;
  s.access_key_id = *id;
  s.secret_access_key = *secret;
  return s;
}

/// The `profile` section of an INI-style credentials file: key = value lines, '#'/';' comments.
/// nullopt when the file or the section does not exist.
std::optional<AwsSigV4> from_credentials_file(const std::string& file, const std::string& profile) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  bool in_section = false, found = false;
  std::optional<std::string> id, secret, token;
  std::string line;
  while (std::getline(in, line)) {
    const std::string t = trimmed(line);
    if (t.empty() || t.front() == '#' || t.front() == ';') continue;
    if (t.front() == '[' && t.back() == ']') {
      in_section = trimmed(std::string_view(t).substr(1, t.size() - 2)) == profile;
      found = found || in_section;
      continue;
    }
    const std::size_t eq = t.find('=');
    if (!in_section || eq == std::string::npos) continue;
    const std::string name = trimmed(std::string_view(t).substr(0, eq));
    std::string value = trimmed(std::string_view(t).substr(eq + 1));
    if (value.empty()) continue;
    if (name == "aws_access_key_id") id = std::move(value);
    if (name == "aws_secret_access_key") secret = std::move(value);
    if (name == "aws_session_token") token = std::move(value);
  }
  if (!found) return std::nullopt;
  const std::string where = file + " [" + profile + "]";
  std::optional<AwsSigV4> s =
      pair(id, secret, where + " aws_access_key_id", where + " aws_secret_access_key");
  if (s && token) s->session_token = *token;
  if (!s) {
    throw invalid_parameter(where, "section has no aws_access_key_id and aws_secret_access_key");
  }
  return s;
}

}  // namespace

std::optional<std::string> process_environment(const std::string& name) {
  const char* v = std::getenv(name.c_str());
  if (v == nullptr) return std::nullopt;
  return std::string(v);
}

S3Config resolve_s3_config(const S3Options& options, const EnvironmentLookup& env) {
  S3Config c;
  if (!options.endpoint.empty()) {
    c.endpoint = checked_endpoint(options.endpoint, "s3 endpoint");
  } else if (const auto e = lookup(env, "AWS_ENDPOINT_URL_S3")) {
    c.endpoint = checked_endpoint(*e, "AWS_ENDPOINT_URL_S3");
  } else if (const auto e2 = lookup(env, "AWS_ENDPOINT_URL")) {
    c.endpoint = checked_endpoint(*e2, "AWS_ENDPOINT_URL");
  }

  std::string region_source = "s3 region";
  c.region = options.region;
  if (c.region.empty()) {
    region_source = "AWS_REGION";
    if (auto r = lookup(env, "AWS_REGION")) {
      c.region = *r;
    } else if (auto r2 = lookup(env, "AWS_DEFAULT_REGION")) {
      region_source = "AWS_DEFAULT_REGION";
      c.region = *r2;
    } else {
      c.region = "us-east-1";
    }
  }
  // The region becomes part of a host name and of libcurl's "aws:amz:<region>:s3".
  const bool region_ok =
      c.region.size() <= 64 && std::all_of(c.region.begin(), c.region.end(), [](char ch) {
        return std::islower(static_cast<unsigned char>(ch)) ||
               std::isdigit(static_cast<unsigned char>(ch)) || ch == '-';
      });
  if (!region_ok) {
    throw invalid_parameter(region_source, "'" + c.region + "' is not a region name (a-z 0-9 -)");
  }

  if (options.anonymous || truthy(lookup(env, "AWS_NO_SIGN_REQUEST"))) {
    c.credentials_source = "anonymous (asked for)";
  } else if (auto s = pair(options.access_key_id.empty()
                               ? std::nullopt
                               : std::optional<std::string>(options.access_key_id),
                           options.secret_access_key.empty()
                               ? std::nullopt
                               : std::optional<std::string>(options.secret_access_key),
                           "access_key_id", "secret_access_key")) {
    s->session_token = options.session_token;
    c.credentials = std::move(s);
    c.credentials_source = "options";
  } else if (auto e = pair(lookup(env, "AWS_ACCESS_KEY_ID"), lookup(env, "AWS_SECRET_ACCESS_KEY"),
                           "AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY")) {
    e->session_token = lookup(env, "AWS_SESSION_TOKEN").value_or("");
    c.credentials = std::move(e);
    c.credentials_source = "environment";
  } else {
    const std::optional<std::string> profile = lookup(env, "AWS_PROFILE");
    std::optional<std::string> file = lookup(env, "AWS_SHARED_CREDENTIALS_FILE");
    if (!file) {
      if (const auto home = lookup(env, "HOME")) file = *home + "/.aws/credentials";
    }
    std::optional<AwsSigV4> f;
    if (file) f = from_credentials_file(*file, profile.value_or("default"));
    if (f) {
      c.credentials = std::move(f);
      c.credentials_source = *file + " [" + profile.value_or("default") + "]";
    } else if (profile) {
      throw invalid_parameter("AWS_PROFILE", "profile '" + *profile + "' not found in " +
                                                 file.value_or("(no credentials file)"));
    } else {
      c.credentials_source = "anonymous (no credentials found)";
    }
  }
  if (c.credentials) c.credentials->region = c.region;
  return c;
}

}  // namespace resoct
