// Sources in an S3-compatible object store (s3rver on loopback, started by the test): signed and
// anonymous reads give the same bricks as the local files, for brick stores (Range reads) and
// OME-Zarr images (missing chunks as fill value); bad credentials and a missing bucket are clear
// errors, sent once (no retries).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/base/random_access_file.hpp"
#include "resoct/io/http/s3_store.hpp"
#include "support/brick_compare.hpp"
#include "support/expect_error.hpp"
#include "support/generated_data.hpp"
#include "support/http_test_server.hpp"
#include "support/s3_test_server.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::S3TestServer;
using resoct::test::TempDir;

namespace {

const std::string& zarr_dir() {
  static const std::string dir = test::python_generated_dir(
      RESOCT_BINARY_DIR "/test-data", "ome-zarr", RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
  return dir;
}

const std::string& zarr_v3_dir() {
  static const std::string dir =
      test::python_generated_dir(RESOCT_BINARY_DIR "/test-data", "ome-zarr-v3",
                                 RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr_v3.py");
  return dir;
}

/// OME-Zarr 0.5 images in the bucket: sharded (index at the end, so read by suffix range or
/// its fallback) and an int16 one with missing shards.
const char* const kV3Images[] = {"zstd_u2_shard-end.zarr", "typed_fill_i2.zarr"};

const BrickLayout kLayout{glm::uvec3(8), 1};

/// Bucket "data": cells.rbs (a brick store), images/pyramid_u2.zarr and images/fill_u1.zarr
/// (OME-Zarr 0.4), images/<kV3Images> (OME-Zarr 0.5).
/// Bucket "empty": nothing.
class S3Store : public ::testing::Test {
 protected:
  void SetUp() override {
    RESOCT_SKIP_WITHOUT_S3_SERVER();
    ASSERT_FALSE(zarr_dir().empty());
    ASSERT_FALSE(zarr_v3_dir().empty());
    auto src = make_procedural_source("procedural:tubes:48x40x24", kLayout);
    write_brick_store(*src, dir_.file("cells.rbs"));
    std::filesystem::create_directory(dir_.file("images"));
    for (const char* name : {"pyramid_u2.zarr", "fill_u1.zarr"}) {
      std::filesystem::create_directory_symlink(zarr_dir() + "/" + name,
                                                dir_.file("images/" + std::string(name)));
    }
    for (const char* name : kV3Images) {
      std::filesystem::create_directory_symlink(zarr_v3_dir() + "/" + name,
                                                dir_.file("images/" + std::string(name)));
    }
    server_ = std::make_unique<S3TestServer>(
        std::vector<S3TestServer::Bucket>{{"data", dir_.path().string()}, {"empty", ""}}, token_);
  }

  /// Options for the test server with `secret` (s3rver's own when empty).
  SourceOptions options(const std::string& secret = test::kS3Secret) const {
    SourceOptions o;
    o.http = test::fast_http_options();
    o.s3.endpoint = server_->endpoint();
    o.s3.access_key_id = test::kS3AccessKey;
    o.s3.secret_access_key = secret;
    o.s3.session_token = token_;
    return o;
  }

  S3Config config(const std::string& secret = test::kS3Secret) const {
    return resolve_s3_config(options(secret).s3, [](const std::string&) { return std::nullopt; });
  }

  TempDir dir_;
  std::string token_;
  std::unique_ptr<S3TestServer> server_;
};

class S3StoreWithToken : public S3Store {
 protected:
  void SetUp() override {
    token_ = "session-token-1";
    S3Store::SetUp();
  }
};

}  // namespace

TEST_F(S3Store, SignedBrickStoreReadsEqualTheLocalFile) {
  const BrickStoreSource local(dir_.file("cells.rbs"));
  const auto remote = open_source("s3://data/cells.rbs", kLayout, options());
  EXPECT_EQ(remote->name(), "s3://data/cells.rbs");
  test::expect_same_bricks(local, *remote);
}

TEST_F(S3Store, SignedOmeZarrReadsEqualTheLocalImage) {
  for (const char* name : {"pyramid_u2", "fill_u1"}) {  // fill_u1 has missing chunks
    const auto local = open_ome_zarr(zarr_dir() + "/" + name + ".zarr", kLayout);
    const auto remote =
        open_source("s3://data/images/" + std::string(name) + ".zarr/", kLayout, options());
    test::expect_same_bricks(*local, *remote);
  }
}

TEST_F(S3Store, SignedShardedOmeZarr05ReadsEqualTheLocalImage) {
  for (const char* name : kV3Images) {
    SCOPED_TRACE(name);
    const auto local = open_ome_zarr(zarr_v3_dir() + "/" + name, kLayout);
    const auto remote = open_source("s3://data/images/" + std::string(name), kLayout, options());
    EXPECT_EQ(remote->volume(), local->volume());
    test::expect_same_bricks(*local, *remote);
  }
}

TEST_F(S3Store, AnonymousReadsNeedNoCredentials) {
  SourceOptions o = options("not-the-secret");
  o.s3.anonymous = true;  // the wrong secret is never used
  const auto remote = open_source("s3://data/images/pyramid_u2.zarr", kLayout, o);
  test::expect_same_bricks(*open_ome_zarr(zarr_dir() + "/pyramid_u2.zarr", kLayout), *remote);
  const auto store = open_s3_store("s3://data", resolve_s3_config(o.s3), o.http);
  EXPECT_FALSE(store->options().aws_sigv4.has_value());
  EXPECT_TRUE(store->get("cells.rbs", 1 << 30).has_value());
}

TEST_F(S3Store, SignedRangeReadsReturnTheFileBytes) {
  const auto file = open_s3_object("s3://data/cells.rbs", config(), test::fast_http_options());
  const ReadFile local_file(dir_.file("cells.rbs"));
  std::vector<std::byte> local(local_file.size());
  local_file.read_at(0, local);
  ASSERT_EQ(file->size(), local.size());
  for (const std::uint64_t offset : {std::uint64_t(0), std::uint64_t(7), local.size() / 2}) {
    std::vector<std::byte> got(std::min<std::size_t>(1000, local.size() - offset));
    file->read_at(offset, got);
    EXPECT_TRUE(std::equal(got.begin(), got.end(), local.begin() + std::ptrdiff_t(offset)));
  }
  const auto store = open_s3_store("s3://data", config(), test::fast_http_options());
  const auto tail = store->get_range("cells.rbs", local.size() - 5, 5);
  EXPECT_TRUE(std::equal(tail.begin(), tail.end(), local.end() - 5));
  EXPECT_RESOCT_ERROR(store->get_range("cells.rbs", local.size() - 5, 10), ErrorCode::truncated,
                      "cells.rbs");
  EXPECT_EQ(store->stats().retries, 0u);
  EXPECT_EQ(store->stats().connections, 1u);  // keep-alive: signed requests share a connection
}

TEST_F(S3Store, AWrongSecretIsOneClearErrorNamingBucketAndKey) {
  const std::string secret = "wrong-secret-7f3a";
  const auto store = open_s3_store("s3://data/images", config(secret), test::fast_http_options());
  try {
    store->get("pyramid_u2.zarr/.zattrs", 1 << 20);
    ADD_FAILURE() << "a wrong secret was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.code(), ErrorCode::io);
    EXPECT_NE(what.find("/data/images/pyramid_u2.zarr/.zattrs"), std::string::npos) << what;
    EXPECT_NE(what.find("HTTP 403 SignatureDoesNotMatch"), std::string::npos) << what;
    EXPECT_EQ(what.find(secret), std::string::npos) << "the secret leaked: " << what;
  }
  // A 4xx is not transient: one request, no retry storm.
  EXPECT_EQ(store->stats().requests, 1u);
  EXPECT_EQ(store->stats().retries, 0u);
  EXPECT_RESOCT_ERROR(open_source("s3://data/cells.rbs", kLayout, options(secret)), ErrorCode::io,
                      "SignatureDoesNotMatch");
}

TEST_F(S3Store, AnUnknownAccessKeyIsAClearError) {
  SourceOptions o = options();
  o.s3.access_key_id = "NOSUCHKEY";
  EXPECT_RESOCT_ERROR(open_source("s3://data/cells.rbs", kLayout, o), ErrorCode::io,
                      "InvalidAccessKeyId");
}

TEST_F(S3Store, AMissingBucketIsAnErrorAndAMissingKeyIsAbsence) {
  EXPECT_RESOCT_ERROR(open_source("s3://nosuchbucket/x.zarr", kLayout, options()), ErrorCode::io,
                      "NoSuchBucket");
  const auto gone = open_s3_store("s3://nosuchbucket", config(), test::fast_http_options());
  EXPECT_RESOCT_ERROR(gone->get("0/0.0.0", 1 << 20), ErrorCode::io, "/nosuchbucket/0/0.0.0");
  EXPECT_EQ(gone->stats().retries, 0u);
  const auto empty = open_s3_store("s3://empty", config(), test::fast_http_options());
  EXPECT_FALSE(empty->get("0/0.0.0", 1 << 20).has_value());
  EXPECT_RESOCT_ERROR(open_source("s3://empty/nothing.rbs", kLayout, options()), ErrorCode::io,
                      "s3://empty/nothing.rbs");
  EXPECT_RESOCT_ERROR(open_s3_object("s3://empty", config(), {}), ErrorCode::invalid_argument,
                      "names a bucket, not an object");
}

TEST_F(S3StoreWithToken, TheSessionTokenIsSentAndSigned) {
  const BrickStoreSource local(dir_.file("cells.rbs"));
  test::expect_same_bricks(local, *open_source("s3://data/cells.rbs", kLayout, options()));
  SourceOptions o = options();
  o.s3.session_token = "another-token";
  EXPECT_RESOCT_ERROR(open_source("s3://data/cells.rbs", kLayout, o), ErrorCode::io,
                      "InvalidToken");
}
