// Brick stores read over HTTP by Range requests: every brick equals the local read, with and
// without server-side Range support; bad URLs and vanished files give errors naming the URL, and
// a brick that fails over HTTP is reported once by the loader with the URL.

#include <gtest/gtest.h>

#include <filesystem>

#include "resoct/engine/brick_loader.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/http/http_store.hpp"
#include "resoct/io/http/open_random_access_file.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/brick_compare.hpp"
#include "support/expect_error.hpp"
#include "support/http_test_server.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::HttpTestServer;
using resoct::test::TempDir;

namespace {

class HttpBrickStore : public ::testing::Test {
 protected:
  void SetUp() override {
    auto src = make_procedural_source("procedural:tubes:48x40x24", BrickLayout{glm::uvec3(8), 1});
    write_brick_store(*src, dir_.file("cells.rbs"));
    std::ofstream(dir_.file("not_a_store.bin")) << "hello, this is not a brick store";
    server_ =
        std::make_unique<HttpTestServer>(HttpTestServer::default_script(), dir_.path().string());
  }
  TempDir dir_;
  std::unique_ptr<HttpTestServer> server_;
};

}  // namespace

TEST_F(HttpBrickStore, EveryBrickEqualsTheLocalRead) {
  const BrickStoreSource local(dir_.file("cells.rbs"));
  for (const char* mode : {"ok", "norange"}) {
    const std::string url = server_->base(mode) + "/cells.rbs";
    const auto remote = open_source(url);
    EXPECT_EQ(remote->name(), url);
    test::expect_same_bricks(local, *remote);
    const Box3 region{glm::i64vec3(3, 5, 1), glm::i64vec3(40, 30, 17)};
    for (std::uint32_t c = 0; c < remote->volume().channels; ++c) {
      const RegionMeta a = local.region_meta(c, region), b = remote->region_meta(c, region);
      EXPECT_EQ(a.min, b.min);
      EXPECT_EQ(a.max, b.max);
    }
  }
}

TEST_F(HttpBrickStore, BadUrlsAreErrorsNamingTheUrl) {
  const std::string missing = server_->base("ok") + "/nothing.rbs";
  EXPECT_RESOCT_ERROR(open_source(missing), ErrorCode::io, missing);
  const std::string foreign = server_->base("ok") + "/not_a_store.bin";
  EXPECT_RESOCT_ERROR(open_source(foreign), ErrorCode::invalid_argument, foreign);
  EXPECT_RESOCT_ERROR(open_source(server_->base("ok") + "/cells.rbs?x=1"),
                      ErrorCode::invalid_argument, "query");
  EXPECT_RESOCT_ERROR(open_random_access_file("http://127.0.0.1:1/"), ErrorCode::invalid_argument,
                      "does not name a file");
  // Nothing listens on port 1: the zarr probe fails, naming the URL.
  HttpOptions quick;
  quick.retries = 0;
  EXPECT_RESOCT_ERROR(open_random_access_file("http://127.0.0.1:1/x.rbs", quick), ErrorCode::io,
                      "http://127.0.0.1:1/x.rbs");
}

TEST_F(HttpBrickStore, AFileThatVanishesFailsEachBrickOnceWithTheUrl) {
  const std::string url = server_->base("ok") + "/cells.rbs";
  std::shared_ptr<const BrickSource> remote = open_source(url);
  std::filesystem::remove(dir_.file("cells.rbs"));  // the server now answers 404
  BrickLoader loader(remote, 0, 1 << 20);
  // A brick with a payload (found by its index entry).
  BrickKey key;
  bool found = false;
  const LevelInfo& l0 = remote->hierarchy().level(0);
  for (std::uint32_t i = 0; i < l0.brick_count && !found; ++i) {
    key = BrickKey(0, 0,
                   glm::uvec3(i % l0.bricks.x, (i / l0.bricks.x) % l0.bricks.y,
                              i / (l0.bricks.x * l0.bricks.y)));
    found = !remote->brick_meta(key).constant;
  }
  ASSERT_TRUE(found);
  const LoadRequest r{key, 1, 0, 0};
  loader.request(std::span(&r, 1));
  loader.run_queued(1);
  const auto failures = loader.take_failures();
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_NE(failures[0].message.find(url), std::string::npos) << failures[0].message;
  EXPECT_NE(failures[0].message.find("not found"), std::string::npos) << failures[0].message;
  loader.request(std::span(&r, 1));
  EXPECT_EQ(loader.run_queued(1), 0u);  // never requested again
  EXPECT_TRUE(loader.take_failures().empty());
}
