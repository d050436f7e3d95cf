#pragma once
// The tools' options for remote sources (S3 endpoint, unsigned access), shared so that every tool
// that opens a source spec spells them alike. HTTP behaviour keeps its defaults.

#include "resoct/io/open_source.hpp"

namespace CLI {
class App;
}

namespace resoct::tools {

/// Adds --s3-endpoint URL and --no-sign-request to `app`, writing into `options` (group
/// "Remote sources"). Both override the environment (AWS_ENDPOINT_URL_S3, AWS_NO_SIGN_REQUEST).
void add_source_options(CLI::App& app, SourceOptions& options);

/// True for the specs open_source reads over the network (http(s)://, s3://).
bool is_remote_spec(std::string_view spec) noexcept;

}  // namespace resoct::tools
