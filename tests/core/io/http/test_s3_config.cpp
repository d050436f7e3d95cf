// s3:// specs and S3 configuration without a server: spec parsing and bucket name rules, the
// endpoint / region / credentials order (options, environment, shared credentials file), and
// the bucket addressing (path style with an endpoint, virtual-hosted on AWS).

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "resoct/io/open_source.hpp"
#include "resoct/io/http/s3_store.hpp"
#include "support/expect_error.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;

namespace {

EnvironmentLookup env_of(std::map<std::string, std::string> vars) {
  return [vars = std::move(vars)](const std::string& name) -> std::optional<std::string> {
    const auto it = vars.find(name);
    if (it == vars.end()) return std::nullopt;
    return it->second;
  };
}

}  // namespace

TEST(S3Config, SpecsSplitIntoBucketAndKey) {
  EXPECT_TRUE(is_s3_url("S3://b"));
  EXPECT_FALSE(is_s3_url("s3:/b"));
  const S3Path p = parse_s3_url("s3://my-bucket/dir/x.zarr/");
  EXPECT_EQ(p.bucket, "my-bucket");
  EXPECT_EQ(p.key, "dir/x.zarr");
  EXPECT_EQ(parse_s3_url("s3://my.bucket.1").key, "");
}

TEST(S3Config, BadSpecsAreErrorsNamingTheSpec) {
  for (const char* spec : {"s3://", "s3:///key", "s3://ab/k", "s3://Upper/k", "s3://a..b/k",
                           "s3://-ab/k", "s3://192.168.1.1/k", "s3://b_c/k", "s3://bucket/a//b",
                           "s3://bucket/a/../b", "s3://bucket/k?versionId=1"}) {
    EXPECT_RESOCT_ERROR(parse_s3_url(spec), ErrorCode::invalid_argument, spec);
    EXPECT_RESOCT_ERROR(open_source(spec), ErrorCode::invalid_argument, spec);
  }
}

TEST(S3Config, EndpointAndRegionComeFromOptionsThenTheEnvironment) {
  const auto none = env_of({});
  S3Config c = resolve_s3_config({}, none);
  EXPECT_EQ(c.endpoint, "");
  EXPECT_EQ(c.region, "us-east-1");
  EXPECT_FALSE(c.credentials.has_value());

  const auto env = env_of({{"AWS_ENDPOINT_URL", "http://general:1"},
                           {"AWS_ENDPOINT_URL_S3", "http://minio:9000/"},
                           {"AWS_DEFAULT_REGION", "eu-west-1"}});
  c = resolve_s3_config({}, env);
  EXPECT_EQ(c.endpoint, "http://minio:9000");
  EXPECT_EQ(c.region, "eu-west-1");
  EXPECT_EQ(resolve_s3_config({}, env_of({{"AWS_ENDPOINT_URL", "https://ceph"}})).endpoint,
            "https://ceph");
  EXPECT_EQ(resolve_s3_config(
                {}, env_of({{"AWS_REGION", "ap-south-1"}, {"AWS_DEFAULT_REGION", "eu-west-1"}}))
                .region,
            "ap-south-1");
  S3Options o;
  o.endpoint = "http://127.0.0.1:9";
  o.region = "us-west-2";
  c = resolve_s3_config(o, env);
  EXPECT_EQ(c.endpoint, "http://127.0.0.1:9");
  EXPECT_EQ(c.region, "us-west-2");
}

TEST(S3Config, BadEndpointsAndRegionsAreErrorsNamingTheirSource) {
  S3Options o;
  o.endpoint = "ftp://host";
  EXPECT_RESOCT_ERROR(resolve_s3_config(o, env_of({})), ErrorCode::invalid_argument, "ftp://host");
  EXPECT_RESOCT_ERROR(resolve_s3_config({}, env_of({{"AWS_ENDPOINT_URL_S3", "minio:9000"}})),
                      ErrorCode::invalid_argument, "AWS_ENDPOINT_URL_S3");
  EXPECT_RESOCT_ERROR(resolve_s3_config({}, env_of({{"AWS_REGION", "eu/west"}})),
                      ErrorCode::invalid_argument, "AWS_REGION");
  SourceOptions bad;
  bad.s3.endpoint = "not a url";
  EXPECT_RESOCT_ERROR(open_source("s3://bucket/x.zarr", {}, bad), ErrorCode::invalid_argument,
                      "'s3://bucket/x.zarr': parameter 's3 endpoint': 'not a url'");
}

TEST(S3Config, CredentialsComeFromOptionsThenEnvironmentThenFile) {
  resoct::test::TempDir dir;
  const std::string file = dir.file("credentials");
  std::ofstream(file) << "# comment\n[default]\naws_access_key_id = FILEKEY\n"
                         "aws_secret_access_key = filesecret\n\n[other]\n"
                         "aws_access_key_id=OTHERKEY\naws_secret_access_key=othersecret\n"
                         "aws_session_token=othertoken\n[half]\naws_access_key_id=HALF\n";
  std::map<std::string, std::string> vars{{"AWS_SHARED_CREDENTIALS_FILE", file},
                                          {"AWS_ACCESS_KEY_ID", "ENVKEY"},
                                          {"AWS_SECRET_ACCESS_KEY", "envsecret"},
                                          {"AWS_SESSION_TOKEN", "envtoken"},
                                          {"AWS_REGION", "eu-central-1"}};
  S3Options explicit_keys;
  explicit_keys.access_key_id = "OPTKEY";
  explicit_keys.secret_access_key = "optsecret";
  S3Config c = resolve_s3_config(explicit_keys, env_of(vars));
  EXPECT_EQ(c.credentials->access_key_id, "OPTKEY");
  EXPECT_EQ(c.credentials->session_token, "");
  EXPECT_EQ(c.credentials->region, "eu-central-1");

  c = resolve_s3_config({}, env_of(vars));
  EXPECT_EQ(c.credentials->access_key_id, "ENVKEY");
  EXPECT_EQ(c.credentials->secret_access_key, "envsecret");
  EXPECT_EQ(c.credentials->session_token, "envtoken");
  EXPECT_EQ(c.credentials_source, "environment");

  vars.erase("AWS_ACCESS_KEY_ID");
  EXPECT_RESOCT_ERROR(resolve_s3_config({}, env_of(vars)), ErrorCode::invalid_argument,
                      "AWS_ACCESS_KEY_ID");
  vars.erase("AWS_SECRET_ACCESS_KEY");
  c = resolve_s3_config({}, env_of(vars));
  EXPECT_EQ(c.credentials->access_key_id, "FILEKEY");
  EXPECT_EQ(c.credentials->secret_access_key, "filesecret");
  vars["AWS_PROFILE"] = "other";
  c = resolve_s3_config({}, env_of(vars));
  EXPECT_EQ(c.credentials->access_key_id, "OTHERKEY");
  EXPECT_EQ(c.credentials->session_token, "othertoken");
  vars["AWS_PROFILE"] = "nosuch";
  EXPECT_RESOCT_ERROR(resolve_s3_config({}, env_of(vars)), ErrorCode::invalid_argument, "nosuch");
  vars["AWS_PROFILE"] = "half";
  try {
    resolve_s3_config({}, env_of(vars));
    ADD_FAILURE() << "a half profile was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("aws_secret_access_key"), std::string::npos);
  }
  vars.erase("AWS_PROFILE");

  // Anonymous when asked, whatever is configured; and when nothing is.
  S3Options anonymous = explicit_keys;
  anonymous.anonymous = true;
  EXPECT_FALSE(resolve_s3_config(anonymous, env_of(vars)).credentials.has_value());
  vars["AWS_NO_SIGN_REQUEST"] = "true";
  EXPECT_FALSE(resolve_s3_config({}, env_of(vars)).credentials.has_value());
  EXPECT_FALSE(
      resolve_s3_config({}, env_of({{"HOME", dir.file("nohome")}})).credentials.has_value());
}

TEST(S3Config, BucketsAreAddressedByPathWithAnEndpointElseVirtualHosted) {
  S3Config c;
  c.region = "eu-west-1";
  EXPECT_EQ(s3_bucket_url(c, "data"), "https://data.s3.eu-west-1.amazonaws.com");
  EXPECT_EQ(s3_bucket_url(c, "my.data"), "https://s3.eu-west-1.amazonaws.com/my.data");
  c.endpoint = "http://127.0.0.1:9000";
  EXPECT_EQ(s3_bucket_url(c, "data"), "http://127.0.0.1:9000/data");
  const auto store = open_s3_store("s3://data/dir/x y.zarr", c);
  EXPECT_EQ(store->location("0/.zarray"), "http://127.0.0.1:9000/data/dir/x%20y.zarr/0/.zarray");
}

TEST(S3Config, SigningOptionsAreValidatedWithoutEchoingSecrets) {
  HttpOptions o;
  o.aws_sigv4 = AwsSigV4{};
  o.aws_sigv4->access_key_id = "KEY";
  o.aws_sigv4->secret_access_key = "secret\nwith-newline";
  try {
    o.validate();
    ADD_FAILURE() << "a secret with a control character was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find("with-newline"), std::string::npos) << e.what();
  }
  o.aws_sigv4->secret_access_key = "ok";
  o.aws_sigv4->region = "us:east";
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "aws_sigv4.region");
}
