#include "support/source_options.hpp"

#include <CLI/CLI.hpp>

namespace resoct::tools {

void add_source_options(CLI::App& app, SourceOptions& options) {
  const char* group = "Remote sources";
  app.add_option("--s3-endpoint", options.s3.endpoint,
                 "S3-compatible server for s3:// specs, http(s)://host[:port] (MinIO, Ceph; "
                 "path-style addressing); default AWS_ENDPOINT_URL_S3, AWS_ENDPOINT_URL, else AWS")
      ->group(group);
  app.add_flag("--no-sign-request", options.s3.anonymous,
               "read s3:// specs anonymously (public buckets), ignoring any credentials")
      ->group(group);
}

bool is_remote_spec(std::string_view spec) noexcept {
  return is_http_url(spec) || is_s3_url(spec);
}

}  // namespace resoct::tools
