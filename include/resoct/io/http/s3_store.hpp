#pragma once
/// \file
/// Objects in S3-compatible object stores (AWS S3, MinIO, Ceph, GCS interoperability) named by
/// "s3://bucket/key" specs. An S3 store is an HttpStore (http_store.hpp) whose base URL is the
/// bucket's address and whose requests are SigV4-signed, so Range reads, retries, keep-alive and
/// error reporting are the HTTP ones. Spec, configuration order and errors: docs/http.md,
/// "S3-compatible object stores".

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "resoct/io/http/http_store.hpp"

namespace resoct {

class RandomAccessFile;

/// A parsed "s3://bucket[/key]" spec.
struct S3Path {
  std::string bucket;
  std::string key;  ///< "" for the bucket's root; else a valid store key (check_store_key)
};

/// True for "s3://..." (case-insensitive scheme).
bool is_s3_url(std::string_view s) noexcept;

/// Parses "s3://bucket[/key][/]". The bucket must follow S3's naming rules (3-63 characters of
/// a-z 0-9 . -, starting and ending with a letter or digit, no "..", not an IP address); the key
/// is taken literally (no percent-decoding) and must be a valid store key. Throws
/// Error(invalid_argument) naming the spec otherwise (also for a query or fragment).
S3Path parse_s3_url(std::string_view spec);

/// How to reach and authenticate to the store. Empty fields are taken from the environment, as
/// the AWS CLI reads it (see resolve_s3_config).
struct S3Options {
  /// "http(s)://host[:port]" of an S3-compatible server (MinIO, s3rver, Ceph), addressed in path
  /// style "<endpoint>/<bucket>/<key>". Empty: AWS_ENDPOINT_URL_S3, then AWS_ENDPOINT_URL, then
  /// AWS itself.
  std::string endpoint;
  /// Empty: AWS_REGION, then AWS_DEFAULT_REGION, then "us-east-1".
  std::string region;
  /// Send unsigned requests (public buckets) even when credentials are configured. Also set by
  /// AWS_NO_SIGN_REQUEST=1/true/yes.
  bool anonymous = false;
  /// Explicit credentials; when empty: AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY /
  /// AWS_SESSION_TOKEN, then the AWS_PROFILE (else "default") section of the shared credentials
  /// file (AWS_SHARED_CREDENTIALS_FILE, else ~/.aws/credentials), then anonymous.
  std::string access_key_id;
  std::string secret_access_key;
  std::string session_token;
};

/// S3Options with every choice made.
struct S3Config {
  std::string endpoint;  ///< "" for AWS
  std::string region;
  std::optional<AwsSigV4> credentials;  ///< nullopt: anonymous
  std::string credentials_source;       ///< where they came from, for messages ("environment", ...)
};

/// Looks up an environment variable (nullopt when unset); tests pass their own.
using EnvironmentLookup = std::function<std::optional<std::string>(const std::string&)>;
/// The process environment (std::getenv).
std::optional<std::string> process_environment(const std::string& name);

/// Fills the empty fields of `options` from `env` and the shared credentials file, in the order
/// S3Options documents. Throws Error(invalid_argument) naming the variable or field when only
/// one of key id and secret is given, when the endpoint is not an http(s)://host URL, or when a
/// credentials file section names only one of them. Never puts a secret into a message.
S3Config resolve_s3_config(const S3Options& options,
                           const EnvironmentLookup& env = process_environment);

/// The URL of `bucket`'s root: "<endpoint>/<bucket>" with an endpoint (path style), else
/// "https://<bucket>.s3.<region>.amazonaws.com" (virtual-hosted style), or path style
/// "https://s3.<region>.amazonaws.com/<bucket>" for bucket names with dots (TLS certificates of
/// *.s3.<region>.amazonaws.com do not cover them).
std::string s3_bucket_url(const S3Config& config, std::string_view bucket);

/// An HttpStore for the objects below "s3://bucket/prefix" (keys are relative to the prefix),
/// signing requests when config has credentials. `http` supplies timeouts and retries; its
/// aws_sigv4 is replaced. Throws Error(invalid_argument) naming the spec for a bad spec.
std::shared_ptr<HttpStore> open_s3_store(std::string_view spec, const S3Config& config,
                                         HttpOptions http = {});

/// The object "s3://bucket/key" as a RandomAccessFile read by Range requests (its size from a
/// HEAD request); its path() is the spec. Throws Error(invalid_argument) naming the spec for a
/// bad spec or an empty key, Error(io) naming the URL when the object does not exist or cannot
/// be read.
std::unique_ptr<RandomAccessFile> open_s3_object(std::string_view spec, const S3Config& config,
                                                 HttpOptions http = {});

}  // namespace resoct
