// OME-Zarr over HTTP: open_source of a URL reads the same bricks as the local directory (stored
// and computed levels, missing chunks as fill value), and a URL map spreads a level over a
// second server.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/http/http_store.hpp"
#include "resoct/io/open_source.hpp"
#include "support/brick_compare.hpp"
#include "support/expect_error.hpp"
#include "support/generated_data.hpp"
#include "support/http_test_server.hpp"

using namespace resoct;
using resoct::test::HttpTestServer;

namespace {

const std::string& data_dir() {
  static const std::string dir = test::python_generated_dir(
      RESOCT_BINARY_DIR "/test-data", "ome-zarr", RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
  return dir;
}

int server_requests(const HttpTestServer& s) {
  HttpStore stats(parse_url_map("http://127.0.0.1:" + std::to_string(s.port())));
  const auto b = stats.get("_stats", 1 << 16);
  return nlohmann::json::parse(
             std::string(reinterpret_cast<const char*>(b->data()), b->size()))["requests"]
      .get<int>();
}

}  // namespace

TEST(HttpOmeZarr, UrlReadsTheSameBricksAsTheDirectory) {
  ASSERT_FALSE(data_dir().empty());
  HttpTestServer server(HttpTestServer::default_script(), data_dir());
  const BrickLayout layout{glm::uvec3(8), 1};
  for (const char* name : {"pyramid_u2", "fill_u1"}) {
    const auto local = open_ome_zarr(data_dir() + "/" + name + ".zarr", layout);
    const std::string url = server.base("ok") + "/" + name + ".zarr";
    const auto remote = open_source(url, layout);
    test::expect_same_bricks(*local, *remote);
  }
}

TEST(HttpOmeZarr, UrlMapSendsALevelToASecondServer) {
  ASSERT_FALSE(data_dir().empty());
  HttpTestServer a(HttpTestServer::default_script(), data_dir());
  HttpTestServer b(HttpTestServer::default_script(), data_dir());  // a mirror
  const BrickLayout layout{glm::uvec3(8), 1};
  const std::string spec = a.base("ok") + "/pyramid_u2.zarr,1=" + b.base("ok") + "/pyramid_u2.zarr";
  const auto remote = open_source(spec, layout);
  const auto local = open_ome_zarr(data_dir() + "/pyramid_u2.zarr", layout);
  test::expect_same_bricks(*local, *remote);
  // Both hosts served requests (the stats requests themselves are not counted yet).
  EXPECT_GT(server_requests(a), 0);
  EXPECT_GT(server_requests(b), 0);
}

TEST(HttpOmeZarr, AUrlThatIsNeitherZarrNorStoreNamesTheUrl) {
  ASSERT_FALSE(data_dir().empty());
  HttpTestServer server(HttpTestServer::default_script(), data_dir());
  const std::string url = server.base("ok") + "/manifest.json";
  EXPECT_RESOCT_ERROR(open_source(url), ErrorCode::invalid_argument, url);
}

namespace {

const std::string& v3_data_dir() {
  static const std::string dir =
      test::python_generated_dir(RESOCT_BINARY_DIR "/test-data", "ome-zarr-v3",
                                 RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr_v3.py");
  return dir;
}

}  // namespace

TEST(HttpOmeZarr, ShardedV3BrickReadsTheIndexAndOneInnerChunkNotTheShard) {
  ASSERT_FALSE(v3_data_dir().empty());
  HttpTestServer server(HttpTestServer::default_script(), v3_data_dir());
  // "nosuffix" answers suffix ranges with 200: the store falls back to HEAD + a first-last range.
  for (const char* mode : {"ok", "nosuffix"}) {
    SCOPED_TRACE(mode);
    const std::string name = "raw_u2_one-shard.zarr";  // one 16^3 shard of 2^3 inner 8^3 chunks
    auto store = open_http_store(server.base(mode) + "/" + name, test::fast_http_options());
    OmeZarrOptions o;
    o.pyramid.threads = 1;
    o.pyramid.eager_scan_voxels = 0;  // open reads metadata only
    const BrickLayout layout{glm::uvec3(4), 0};
    const auto remote = open_ome_zarr(store, layout, o);
    const std::uint64_t after_open = store->stats().bytes;
    std::vector<std::byte> out(layout.padded_voxels() * 2);
    remote->read_brick(remote->hierarchy().key_from_linear(0, 0), out);
    const std::uint64_t brick_bytes = store->stats().bytes - after_open;
    const std::uint64_t inner = 8 * 8 * 8 * 2, index = 8 * 16 + 4;
    const std::string shard_key =
        "0/" + remote->array(0).chunk_key(std::vector<std::uint64_t>{0, 0, 0});
    const auto shard_bytes =
        open_directory_store(v3_data_dir() + "/" + name)->get(shard_key, 1 << 20);
    ASSERT_TRUE(shard_bytes) << shard_key;
    const std::uint64_t shard = shard_bytes->size();
    EXPECT_EQ(brick_bytes, inner + index) << "shard of " << shard << " bytes";
    EXPECT_LT(brick_bytes, shard / 2);
    const auto local = open_ome_zarr(v3_data_dir() + "/" + name, layout, o);
    test::expect_same_bricks(*local, *remote);
  }
}
