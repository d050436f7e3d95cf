// HttpStore against a real HTTP server on loopback (tests/support/http_test_server.py): byte
// exactness against the local file, Range handling with and without server support, connection
// reuse, retries, timeouts, truncation, size limits and URL routing.

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "resoct/base/error.hpp"
#include "resoct/io/http/http_store.hpp"
#include "support/expect_error.hpp"
#include "support/http_test_server.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::fast_http_options;
using resoct::test::HttpTestServer;
using resoct::test::TempDir;

namespace {

std::vector<std::byte> random_bytes(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::byte> b(n);
  for (auto& x : b) x = std::byte(rng() & 0xFFu);
  return b;
}

void write_file(const std::string& path, const std::vector<std::byte>& b) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

class HttpStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = random_bytes(300000, 7);
    write_file(dir_.file("blob.bin"), data_);
    std::filesystem::create_directories(dir_.path() / "0");
    write_file(dir_.file("0/1.2.3"), random_bytes(1000, 8));
    server_ =
        std::make_unique<HttpTestServer>(HttpTestServer::default_script(), dir_.path().string());
  }
  HttpStore store(const std::string& mode, HttpOptions o = fast_http_options()) {
    return HttpStore(parse_url_map(server_->base(mode)), o);
  }
  nlohmann::json server_stats() {
    HttpStore s(parse_url_map("http://127.0.0.1:" + std::to_string(server_->port())),
                fast_http_options());
    auto b = s.get("_stats", 1 << 20);
    return nlohmann::json::parse(std::string(reinterpret_cast<const char*>(b->data()), b->size()));
  }
  void reset_server() {
    HttpStore s(parse_url_map("http://127.0.0.1:" + std::to_string(server_->port())),
                fast_http_options());
    ASSERT_TRUE(s.get("_reset", 1 << 20).has_value());
  }

  TempDir dir_;
  std::vector<std::byte> data_;
  std::unique_ptr<HttpTestServer> server_;
};

}  // namespace

TEST(UrlMap, ParsesBaseAndRoutes) {
  const UrlMap m = parse_url_map("http://a/x.zarr/,2=http://b:81/y,labels/0=https://c/z");
  EXPECT_EQ(m.base, "http://a/x.zarr");
  ASSERT_EQ(m.routes.size(), 2u);
  EXPECT_EQ(m.routes[0].first, "2");
  EXPECT_EQ(m.routes[0].second, "http://b:81/y");
  EXPECT_EQ(m.routes[1].first, "labels/0");
  EXPECT_EQ(m.routes[1].second, "https://c/z");
}

TEST(UrlMap, RejectsBadSpecs) {
  EXPECT_RESOCT_ERROR(parse_url_map(""), ErrorCode::invalid_argument, "url_map");
  EXPECT_RESOCT_ERROR(parse_url_map("2=http://b/y"), ErrorCode::invalid_argument, "no base URL");
  EXPECT_RESOCT_ERROR(parse_url_map("http://a,http://b"), ErrorCode::invalid_argument,
                      "more than one base");
  EXPECT_RESOCT_ERROR(parse_url_map("http://a,../x=http://b"), ErrorCode::invalid_argument,
                      "not a valid store key");
  EXPECT_RESOCT_ERROR(parse_url_map("ftp://a"), ErrorCode::invalid_argument, "neither a URL");
  EXPECT_RESOCT_ERROR(parse_url_map("http://"), ErrorCode::invalid_argument, "not an http");
  EXPECT_RESOCT_ERROR(parse_url_map("http://a,1=http://b,1=http://c"), ErrorCode::invalid_argument,
                      "repeated");
}

TEST(UrlMap, RoutesByLongestComponentPrefix) {
  HttpStore s(parse_url_map("http://a/x,1=http://b/x,1/2=http://c/x"));
  EXPECT_EQ(s.location("0/1.2.3"), "http://a/x/0/1.2.3");
  EXPECT_EQ(s.location("1/0.0.0"), "http://b/x/1/0.0.0");
  EXPECT_EQ(s.location("1"), "http://b/x/1");
  EXPECT_EQ(s.location("10/0"), "http://a/x/10/0");  // "1" is not a component prefix of "10"
  EXPECT_EQ(s.location("1/2/5"), "http://c/x/1/2/5");
  EXPECT_EQ(s.location("a b%c"), "http://a/x/a%20b%25c");
}

TEST(HttpOptionsTest, RejectsAbsurdValues) {
  HttpOptions o;
  o.total_timeout_ms = 0;
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "total_timeout_ms");
  o = {};
  o.backoff_max_ms = 1;
  EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "backoff_max_ms");
  o = {};
  o.retries = 1000;
  EXPECT_RESOCT_ERROR(HttpStore(parse_url_map("http://a"), o), ErrorCode::invalid_argument,
                      "retries");
}

TEST_F(HttpStoreTest, GetIsByteExactAndMissingIsAbsent) {
  HttpStore s = store("ok");
  auto b = s.get("blob.bin", data_.size());
  ASSERT_TRUE(b.has_value());
  EXPECT_TRUE(*b == data_);
  EXPECT_FALSE(s.get("nothing/here", 100).has_value());
  EXPECT_FALSE(store("missing").get("blob.bin", 1 << 20).has_value());
  EXPECT_EQ(s.stats().retries, 0u);  // absence is an answer, never retried
  EXPECT_EQ(s.size("blob.bin"), std::optional<std::uint64_t>(data_.size()));
  EXPECT_FALSE(s.size("nothing").has_value());
  EXPECT_RESOCT_ERROR(s.get("../etc/passwd", 10), ErrorCode::invalid_argument, "key");
}

TEST_F(HttpStoreTest, RangesAreByteExactWithAndWithoutServerSupport) {
  std::mt19937 rng(3);
  for (const char* mode : {"ok", "norange"}) {
    HttpStore s = store(mode);
    for (int i = 0; i < 12; ++i) {
      const std::uint64_t size = 1 + rng() % 5000;
      const std::uint64_t offset = rng() % (data_.size() - size + 1);
      const auto got = s.get_range("blob.bin", offset, size);
      ASSERT_EQ(got.size(), size);
      EXPECT_EQ(std::memcmp(got.data(), data_.data() + offset, size), 0) << mode << " " << offset;
    }
    // The last byte, and a range ending exactly at the end.
    EXPECT_EQ(s.get_range("blob.bin", data_.size() - 1, 1)[0], data_.back());
    EXPECT_RESOCT_ERROR(s.get_range("blob.bin", data_.size() - 10, 11), ErrorCode::truncated,
                        "blob.bin");
    EXPECT_RESOCT_ERROR(s.get_range("blob.bin", data_.size() + 5, 1), ErrorCode::truncated,
                        server_->base(mode) + "/blob.bin");
    EXPECT_RESOCT_ERROR(s.get_range("gone.bin", 0, 1), ErrorCode::io, "not found");
    EXPECT_TRUE(s.get_range("blob.bin", 17, 0).empty());
  }
}

TEST_F(HttpStoreTest, ReusesOneConnectionForSequentialRequests) {
  HttpStore s = store("ok");
  reset_server();
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(s.get_range("blob.bin", std::uint64_t(i) * 100, 100).size(), 100u);
  }
  EXPECT_EQ(s.stats().requests, 20u);
  EXPECT_EQ(s.stats().connections, 1u);
  // The server saw one connection from `s` (server_stats() opens one more after the reset).
  EXPECT_EQ(server_stats()["connections"].get<int>(), 2);
}

TEST_F(HttpStoreTest, ParallelReadersAreByteExact) {
  HttpStore s = store("ok");
  constexpr int kThreads = 6, kReads = 15;
  std::vector<int> bad(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      std::mt19937 rng(std::uint32_t(100 + t));
      for (int i = 0; i < kReads; ++i) {
        const std::uint64_t size = 1 + rng() % 20000;
        const std::uint64_t offset = rng() % (data_.size() - size);
        const auto got = s.get_range("blob.bin", offset, size);
        if (got.size() != size || std::memcmp(got.data(), data_.data() + offset, size) != 0) {
          ++bad[std::size_t(t)];
        }
      }
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(bad[std::size_t(t)], 0) << "thread " << t;
  EXPECT_EQ(s.stats().requests, std::uint64_t(kThreads * kReads));
  // At most one connection per handle, and handles are only created for concurrent requests.
  EXPECT_LE(s.stats().connections, std::uint64_t(kThreads));
}

TEST_F(HttpStoreTest, RetriesTransientServerErrors) {
  HttpStore s = store("flaky");
  auto b = s.get("blob.bin", data_.size());
  ASSERT_TRUE(b.has_value());
  EXPECT_TRUE(*b == data_);
  EXPECT_EQ(s.stats().retries, 2u);  // the server fails the first two requests of a path
  const auto r = s.get_range("0/1.2.3", 10, 20);
  EXPECT_EQ(r.size(), 20u);
  EXPECT_EQ(s.stats().retries, 4u);
}

TEST_F(HttpStoreTest, WaitsAsLongAsRetryAfterAsksUpToTheBackoffCap) {
  // /busy answers the first request of each path with 503 and "Retry-After: 1".
  HttpOptions o = fast_http_options();
  o.backoff_max_ms = 2000;
  const auto t0 = std::chrono::steady_clock::now();
  auto b = store("busy", o).get("blob.bin", data_.size());
  const double waited_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(b.has_value());
  EXPECT_TRUE(*b == data_);
  EXPECT_GE(waited_ms, 1000.0);  // not the 10 ms backoff
  // With a cap below the asked second the cap wins (a second path: its own first 503).
  o.backoff_max_ms = 20;
  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_EQ(store("busy", o).get_range("0/1.2.3", 0, 10).size(), 10u);
  const double capped_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  EXPECT_LT(capped_ms, 900.0);
}

TEST_F(HttpStoreTest, GivesUpAfterTheConfiguredRetries) {
  HttpStore s = store("fail");
  EXPECT_RESOCT_ERROR(s.get("blob.bin", 1 << 20), ErrorCode::io,
                      server_->base("fail") + "/blob.bin: HTTP 500 (3 attempts)");
  EXPECT_EQ(s.stats().requests, 3u);
  EXPECT_EQ(s.stats().retries, 2u);
}

TEST_F(HttpStoreTest, StalledServerFailsWithinTheTimeout) {
  HttpOptions o = fast_http_options();
  o.total_timeout_ms = 1000;
  o.retries = 1;
  HttpStore s = store("stall", o);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_RESOCT_ERROR(s.get_range("blob.bin", 0, 10), ErrorCode::io,
                      server_->base("stall") + "/blob.bin");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Two attempts of at most 1 s each plus 10 ms backoff; generous slack for a loaded machine.
  EXPECT_GE(seconds, 1.9);
  EXPECT_LT(seconds, 6.0);
  EXPECT_EQ(s.stats().requests, 2u);
}

TEST_F(HttpStoreTest, TruncatedBodyIsAnErrorNamingTheUrl) {
  HttpStore s = store("truncate");
  EXPECT_RESOCT_ERROR(s.get("blob.bin", 1 << 20), ErrorCode::truncated,
                      server_->base("truncate") + "/blob.bin");
  EXPECT_EQ(s.stats().retries, 2u);  // a cut connection may be transient
  EXPECT_RESOCT_ERROR(s.get_range("blob.bin", 200000, 1000), ErrorCode::truncated, "blob.bin");
}

TEST_F(HttpStoreTest, SizeLimitAbortsTheTransfer) {
  for (const char* mode : {"ok", "norange"}) {
    HttpStore s = store(mode);
    EXPECT_RESOCT_ERROR(s.get("blob.bin", 1000), ErrorCode::out_of_range,
                        server_->base(mode) + "/blob.bin");
    EXPECT_LT(s.stats().bytes, 1000u);
  }
}

TEST_F(HttpStoreTest, RoutesKeysToDifferentServers) {
  TempDir other;
  std::filesystem::create_directories(other.path() / "0");
  const auto other_chunk = random_bytes(500, 9);
  write_file(other.file("0/1.2.3"), other_chunk);
  HttpTestServer second(HttpTestServer::default_script(), other.path().string());
  HttpStore s(parse_url_map(server_->base("ok") + ",0=" + second.base("ok")), fast_http_options());
  auto chunk = s.get("0/1.2.3", 1 << 20);
  ASSERT_TRUE(chunk.has_value());
  EXPECT_TRUE(*chunk == other_chunk);
  auto blob = s.get("blob.bin", data_.size());
  ASSERT_TRUE(blob.has_value());
  EXPECT_TRUE(*blob == data_);
}

TEST(HttpStoreRefused, ConnectionRefusedIsAnIoErrorNamingTheUrl) {
  int port = 0;
  {
    TempDir d;
    HttpTestServer s(HttpTestServer::default_script(), d.path().string());
    port = s.port();
  }  // the server is gone: nothing listens on the port any more
  HttpOptions o = fast_http_options();
  o.retries = 1;
  HttpStore s(parse_url_map("http://127.0.0.1:" + std::to_string(port) + "/ok"), o);
  EXPECT_RESOCT_ERROR(s.get("x", 10), ErrorCode::io,
                      "http://127.0.0.1:" + std::to_string(port) + "/ok/x");
  EXPECT_EQ(s.stats().retries, 1u);
}
