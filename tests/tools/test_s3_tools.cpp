// The tools read s3:// specs: resoct-convert copies an OME-Zarr image out of an S3-compatible
// store (s3rver on loopback) given --s3-endpoint and credentials from the environment, and
// resoct-info reads a brick store anonymously (--no-sign-request); a wrong secret is a one-line
// error that names the error code and not the secret.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/brick_compare.hpp"
#include "support/generated_data.hpp"
#include "support/s3_test_server.hpp"
#include "support/tool_process.hpp"

using resoct::test::S3TestServer;
using resoct::test::shell_quote;
using resoct::test::TempDir;
using resoct::test::ToolRun;

namespace {

const std::string kConvert = RESOCT_CONVERT;
const std::string kInfo = RESOCT_INFO;

class S3Tools : public ::testing::Test {
 protected:
  void SetUp() override {
    RESOCT_SKIP_WITHOUT_S3_SERVER();
    zarr_ = resoct::test::python_generated_dir(RESOCT_BINARY_DIR "/test-data", "ome-zarr",
                                               RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
    ASSERT_FALSE(zarr_.empty());
    std::filesystem::create_directory(data_.file("images"));
    std::filesystem::create_directory_symlink(zarr_ + "/pyramid_u2.zarr",
                                              data_.file("images/pyramid_u2.zarr"));
    const auto src = resoct::make_procedural_source("procedural:tubes:24x20x12",
                                                    resoct::BrickLayout{glm::uvec3(8), 1});
    resoct::write_brick_store(*src, data_.file("cells.rbs"));
    server_ = std::make_unique<S3TestServer>(
        std::vector<S3TestServer::Bucket>{{"data", data_.path().string()}});
    // The tools take credentials from the environment, as the AWS CLI does; nothing else here
    // may point them elsewhere.
    for (const char* v : {"AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_S3", "AWS_PROFILE",
                          "AWS_NO_SIGN_REQUEST", "AWS_SESSION_TOKEN"}) {
      ::unsetenv(v);
    }
    ::setenv("AWS_SHARED_CREDENTIALS_FILE", "/nonexistent", 1);
    ::setenv("AWS_ACCESS_KEY_ID", resoct::test::kS3AccessKey, 1);
    ::setenv("AWS_SECRET_ACCESS_KEY", resoct::test::kS3Secret, 1);
  }

  std::string zarr_;
  TempDir data_, work_;
  std::unique_ptr<S3TestServer> server_;
};

}  // namespace

TEST_F(S3Tools, ConvertReadsAnOmeZarrImageFromTheStore) {
  const std::string out = work_.file("out.rbs");
  const ToolRun r = resoct::test::run_tool_process(
      work_.path().string(), kConvert,
      "s3://data/images/pyramid_u2.zarr " + shell_quote(out) + " --brick 8 --threads 2 " +
          "--s3-endpoint " + shell_quote(server_->endpoint()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const resoct::BrickStoreSource store(out);
  const auto local =
      resoct::open_ome_zarr(zarr_ + "/pyramid_u2.zarr", resoct::BrickLayout{glm::uvec3(8), 1});
  resoct::test::expect_same_bricks(*local, store);
}

TEST_F(S3Tools, InfoReadsAnonymouslyAndAWrongSecretIsOneLine) {
  ::setenv("AWS_ENDPOINT_URL_S3", server_->endpoint().c_str(), 1);
  ToolRun r = resoct::test::run_tool_process(work_.path().string(), kInfo,
                                             "s3://data/cells.rbs --json --no-sign-request");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("24"), std::string::npos) << r.out;

  ::setenv("AWS_SECRET_ACCESS_KEY", "wrong-secret-5c1d", 1);
  r = resoct::test::run_tool_process(work_.path().string(), kInfo, "s3://data/cells.rbs");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("SignatureDoesNotMatch"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/data/cells.rbs"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("wrong-secret-5c1d"), std::string::npos) << r.err;
}
