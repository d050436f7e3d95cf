// Faults injected on loopback over a long camera path: the HTTP test server's /chaos mode answers
// a share of requests with 404, 500, 503 + Retry-After, truncated bodies, wrong Content-Range,
// stalls past the client's timeout and connection resets, in a seeded random interleaving. The
// renderer must keep rendering every frame (substituting what is missing), report each failed
// brick once, never crash or hang, and, once the server heals, converge to exactly the image of
// the same store read from the local file.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "resoct/scene/scene.hpp"
#include "support/http_test_server.hpp"
#include "support/test_views.hpp"

using namespace resoct;

namespace {

using Clock = std::chrono::steady_clock;

// Client options for the fault run: the tests' fast options, with every attempt ending within a
// second (a stall lasts 3 s) and one retry inside the store. The loader's retries do the rest.
HttpOptions fault_http_options() {
  HttpOptions o = test::fast_http_options();
  o.connect_timeout_ms = 500;
  o.total_timeout_ms = 1000;
  o.retries = 1;
  return o;
}

// Frame i of the path: an orbit around the box centre whose distance swings between 1.3 and 3.5,
// so the level of detail, and with it the bricks wanted, keeps changing.
Camera path_camera(int i, int frames) {
  const double a = 2.0 * 3.14159265358979 * 1.5 * double(i) / double(frames);
  const double r = 2.4 + 1.1 * std::sin(2.0 * 3.14159265358979 * 3.0 * double(i) / double(frames));
  Camera c = test::oblique_camera();
  c.eye = {0.5 + r * std::cos(a), 0.5 + 0.6 * std::sin(1.3 * a), 0.5 + r * std::sin(a)};
  return c;
}

}  // namespace

TEST(HttpFaults, RenderingSurvivesInjectedFaultsAndConvergesOnceTheServerHeals) {
  constexpr int kFrames = 500;
  constexpr int kSickFrames = 400;  // the server misbehaves for these, then heals
  test::TempDir dir;
  const auto src = make_procedural_source("procedural:tubes:128x128x128", test::bricks8());
  write_brick_store(*src, dir.file("tubes.rbs"));
  test::HttpTestServer server(test::HttpTestServer::default_script(), dir.path().string());

  Scene scene = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/tubes.json");
  scene.viewport = Viewport{96, 96};
  cpu::register_backend();
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.leaf_size = glm::uvec3(8);
  o.loader_threads = 4;  // stalls hold a thread for a second: others keep loading
  o.retry_failed_after_ms = 50;
  // Caches below what the path visits (about 780 bricks of 1000 bytes, at most 590 in one view):
  // bricks that left the device cache come back from the server.
  o.device_cache_bytes = 650 * 1000;
  o.host_cache_bytes = 64 << 10;

  SourceOptions so;
  so.http = fault_http_options();
  // Opened while the server is healthy: the header and index are read once, at open.
  Renderer remote(open_source(server.base("chaos") + "/tubes.rbs", BrickLayout{}, so), o);
  std::vector<LoadFailure> reported;
  remote.set_failure_callback([&](const LoadFailure& f) { reported.push_back(f); });

  server.get("_reset");
  server.get("_chaos/300/20261124");  // 30 % of requests fail, in a seeded order
  double slowest_ms = 0.0;
  int frames_rendered = 0;
  const auto render = [&](const Scene& s) {
    const auto t0 = Clock::now();
    FrameReport r = remote.render_frame(s);
    slowest_ms =
        std::max(slowest_ms, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    ++frames_rendered;
    EXPECT_EQ(r.image.width(), 96u);  // a frame, whatever arrived
    return r;
  };
  for (int i = 0; i < kFrames; ++i) {
    if (i == kSickFrames) server.get("_chaos/0/0");  // healed
    scene.camera = path_camera(i, kFrames);
    render(scene);
    // Paced like an interactive view, so that loads (and faults) happen during the path.
    std::this_thread::sleep_for(std::chrono::milliseconds(8));
  }
  const nlohmann::json sick = nlohmann::json::parse(server.get("_stats"));

  // Healed: the last view must converge within a deadline (a hang fails here, not in ctest's
  // timeout), with every retry done.
  FrameReport last;
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  do {
    last = render(scene);
    if (!last.converged) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  } while (!last.converged && Clock::now() < deadline);
  ASSERT_TRUE(last.converged) << "no convergence 60 s after the server healed";

  // Each failed brick reported once, with the URL in its message.
  std::set<BrickKey> keys;
  for (const LoadFailure& f : reported) {
    EXPECT_TRUE(keys.insert(f.key).second) << "reported twice: " << f.message;
    EXPECT_NE(f.message.find("/chaos/tubes.rbs"), std::string::npos) << f.message;
  }
  const BrickLoaderStats ls = inspect::loader(remote).stats();
  EXPECT_EQ(ls.failures, reported.size());
  EXPECT_GT(reported.size(), 0u) << "the faults must have failed some bricks";
  EXPECT_GT(ls.retries, 0u);

  // Every kind of fault was injected.
  const nlohmann::json faults = sick["faults"];
  std::uint64_t injected = 0;
  for (const char* kind : {"404", "500", "503", "truncate", "bad_range", "stall", "reset"}) {
    ASSERT_TRUE(faults.contains(kind)) << kind << " never injected: " << faults.dump();
    EXPECT_GT(faults[kind].get<std::uint64_t>(), 0u) << kind;
    injected += faults[kind].get<std::uint64_t>();
  }
  EXPECT_LT(slowest_ms, 5000.0) << "a frame waited for the network";

  // The converged image is the local store's, pixel for pixel.
  RendererOptions lo = o;
  lo.loader_threads = 0;
  lo.retry_failed_after_ms = 0;
  Renderer local(std::make_shared<BrickStoreSource>(dir.file("tubes.rbs")), lo);
  const ConvergeReport ref = local.render_until_converged(scene, 64);
  ASSERT_TRUE(ref.converged);
  ASSERT_EQ(ref.last.image.pixels().size(), last.image.pixels().size());
  for (std::size_t i = 0; i < last.image.pixels().size(); ++i) {
    ASSERT_EQ(ref.last.image.pixels()[i], last.image.pixels()[i]) << "pixel " << i;
  }

  // The figures for the record (docs/testing.md "Fault injection").
  std::printf(
      "fault injection: %d frames, %llu requests while sick, %llu faults injected %s, "
      "%zu bricks failed (each reported once), %llu retries, slowest frame %.1f ms\n",
      frames_rendered, static_cast<unsigned long long>(sick["requests"].get<std::uint64_t>()),
      static_cast<unsigned long long>(injected), faults.dump().c_str(), reported.size(),
      static_cast<unsigned long long>(ls.retries), slowest_ms);
}
