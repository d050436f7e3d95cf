// HTTP redirects may only lead where the caller allowed: the origins (scheme, host, port) of
// the URL map or of HttpOptions::redirect_origins. A redirect to another host or port, to
// file:// or to another scheme is an Error naming the URL and the target, never followed; one
// within the allowed origins is followed as before. Served by tests/support/http_test_server.py
// (modes redirect-*).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <random>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/http/http_store.hpp"
#include "resoct/io/open_source.hpp"
#include "support/expect_error.hpp"
#include "support/http_test_server.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::fast_http_options;
using resoct::test::HttpTestServer;
using resoct::test::TempDir;

namespace {

class HttpRedirectTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(11);
    data_.resize(5000);
    for (auto& b : data_) b = std::byte(rng() & 0xFFu);
    std::ofstream out(dir_.file("blob.bin"), std::ios::binary);
    out.write(reinterpret_cast<const char*>(data_.data()), std::streamsize(data_.size()));
    out.close();
    server_ =
        std::make_unique<HttpTestServer>(HttpTestServer::default_script(), dir_.path().string());
  }
  HttpStore store(const std::string& mode, HttpOptions o = fast_http_options()) {
    return HttpStore(parse_url_map(server_->base(mode)), o);
  }
  std::string url(const std::string& mode) const { return server_->base(mode) + "/blob.bin"; }
  std::string port() const { return std::to_string(server_->port()); }

  TempDir dir_;
  std::vector<std::byte> data_;
  std::unique_ptr<HttpTestServer> server_;
};

TEST_F(HttpRedirectTest, RedirectWithinTheOriginIsFollowed) {
  HttpStore s = store("redirect-ok");
  const auto whole = s.get("blob.bin", 1 << 20);
  ASSERT_TRUE(whole.has_value());
  EXPECT_TRUE(*whole == data_);
  EXPECT_EQ(s.size("blob.bin"), data_.size());
  const auto part = s.get_range("blob.bin", 100, 50);
  EXPECT_TRUE(std::equal(part.begin(), part.end(), data_.begin() + 100));
  EXPECT_FALSE(s.get("absent.bin", 1 << 20).has_value());  // redirected, then 404
  EXPECT_EQ(s.stats().retries, 0u);
}

TEST_F(HttpRedirectTest, RedirectsLeavingTheOriginAreRefusedNamingUrlAndTarget) {
  const std::string host = "http://localhost:" + port() + "/ok/blob.bin";
  const std::string other_port =
      "http://127.0.0.1:" + std::to_string(server_->port() < 65535 ? server_->port() + 1 : 1) +
      "/ok/blob.bin";
  struct Case {
    std::string mode, target;
  };
  for (const Case& c : {Case{"redirect-host", host}, Case{"redirect-port", other_port},
                        // The scheme is part of the origin (so is https -> http, a downgrade).
                        Case{"redirect-https", "https://127.0.0.1:" + port() + "/ok/blob.bin"},
                        Case{"redirect-file", "file:///etc/passwd"},
                        Case{"redirect-ftp", "ftp://127.0.0.1/blob.bin"}}) {
    SCOPED_TRACE(c.mode);
    HttpStore s = store(c.mode);
    const std::string why = url(c.mode) + ": redirect (HTTP 302) to '" + c.target +
                            "' refused: it leaves the allowed origins (http://127.0.0.1:" + port() +
                            ") (1 attempt)";
    EXPECT_RESOCT_ERROR((void)s.get("blob.bin", 1 << 20), ErrorCode::invalid_argument, why);
    EXPECT_RESOCT_ERROR((void)s.size("blob.bin"), ErrorCode::invalid_argument, why);
    EXPECT_RESOCT_ERROR((void)s.get_range("blob.bin", 0, 10), ErrorCode::invalid_argument,
                        "refused: it leaves the allowed origins");
    EXPECT_EQ(s.stats().retries, 0u);  // a refusal is final, not transient
  }
}

TEST_F(HttpRedirectTest, RedirectOriginsAllowListsFurtherHosts) {
  HttpOptions o = fast_http_options();
  o.redirect_origins = {"http://LOCALHOST:" + port() + "/any/path/is/ignored"};
  HttpStore s = store("redirect-host", o);
  const auto whole = s.get("blob.bin", 1 << 20);
  ASSERT_TRUE(whole.has_value());
  EXPECT_TRUE(*whole == data_);
  // The allow-list names origins, not schemes: file:// stays refused.
  EXPECT_RESOCT_ERROR((void)store("redirect-file", o).get("blob.bin", 1 << 20),
                      ErrorCode::invalid_argument, "'file:///etc/passwd' refused");
}

TEST_F(HttpRedirectTest, RedirectLoopEndsAfterFiveHops) {
  HttpStore s = store("redirect-loop");
  EXPECT_RESOCT_ERROR((void)s.get("blob.bin", 1 << 20), ErrorCode::io, "more than 5 redirects");
  EXPECT_EQ(s.stats().requests, 6u);
}

TEST_F(HttpRedirectTest, OpenSourceOfARedirectingUrlIsRefused) {
  EXPECT_RESOCT_ERROR(open_source(server_->base("redirect-file") + "/vol.rbs"),
                      ErrorCode::invalid_argument, "redirect (HTTP 302) to 'file:///etc/passwd'");
}

TEST(HttpRedirectOptions, RedirectOriginsMustBeHttpUrls) {
  for (const std::string bad : {"file:///etc", "ftp://a", "localhost", ""}) {
    SCOPED_TRACE(bad);
    HttpOptions o;
    o.redirect_origins = {bad};
    EXPECT_RESOCT_ERROR(o.validate(), ErrorCode::invalid_argument, "redirect_origins");
    EXPECT_RESOCT_ERROR(HttpStore(parse_url_map("http://a"), o), ErrorCode::invalid_argument,
                        "redirect_origins");
  }
}

}  // namespace
