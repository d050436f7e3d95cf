// S3 objects through the HTTP machinery: an S3 store is an HttpStore whose base URL is the
// bucket's address (s3_bucket_url) plus the spec's key prefix, with SigV4 signing on.
#include "io/http/percent_encoding.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/http/open_random_access_file.hpp"
#include "resoct/io/http/s3_store.hpp"

namespace resoct {

namespace {

std::shared_ptr<HttpStore> store_below(const S3Config& config, const S3Path& path,
                                       std::string_view prefix, HttpOptions http) {
  std::string base = s3_bucket_url(config, path.bucket);
  if (!prefix.empty()) base += "/" + detail::percent_encode_key(prefix);
  http.aws_sigv4 = config.credentials;
  return std::make_shared<HttpStore>(UrlMap{std::move(base), {}}, std::move(http));
}

}  // namespace

std::shared_ptr<HttpStore> open_s3_store(std::string_view spec, const S3Config& config,
                                         HttpOptions http) {
  const S3Path path = parse_s3_url(spec);
  return store_below(config, path, path.key, std::move(http));
}

std::unique_ptr<RandomAccessFile> open_s3_object(std::string_view spec, const S3Config& config,
                                                 HttpOptions http) {
  const S3Path path = parse_s3_url(spec);
  if (path.key.empty()) {
    throw invalid_parameter("spec", "'" + std::string(spec) + "' names a bucket, not an object");
  }
  // The bucket's root as the store, the whole key as the key: messages name both.
  return open_http_object(store_below(config, path, "", std::move(http)), path.key,
                          "s3://" + path.bucket + "/" + path.key);
}

}  // namespace resoct
