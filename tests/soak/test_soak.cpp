// The soak test (opt-in, ctest label "soak"; docs/testing.md "Soak"): ten thousand frames of a
// random camera walk over a four-channel volume, with a device cache of 1/16 of the working set,
// a host cache of 1/16 of the volume and the visible channels remapped at random. Every 100
// frames the renderer's state is checked brick by brick against the source; the process's
// resident memory must stay flat after the warm-up.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include "core/render/test_renderer_support.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/test_views.hpp"

using namespace resoct;

namespace {

/// Resident set size of this process in bytes (/proc/self/statm, second field).
std::uint64_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * std::uint64_t(::sysconf(_SC_PAGESIZE));
}

Scene soak_scene(std::uint32_t a, std::uint32_t b, const Camera& camera) {
  Scene s;
  s.camera = camera;
  s.viewport = Viewport{48, 48};
  for (std::uint32_t c : {a, b}) {
    ChannelSettings ch;
    ch.channel = c;
    ch.tf = TransferFunction({{0.0, {0, 0, 0, 0}},
                              {0.45, {0.2, 0.4, 1.0, 0.0}},
                              {0.7, {1.0, 0.6, 0.2, 0.3}},
                              {1.0, {1.0, 1.0, 1.0, 0.8}}});
    s.channels.push_back(ch);
  }
  return s;
}

}  // namespace

TEST(Soak, TenThousandFramesWithASmallCacheStayConsistentAndFlat) {
  constexpr int kFrames = 10000;
  constexpr int kWarmup = 1000;
  const auto src = std::shared_ptr<const BrickSource>(
      make_procedural_source("procedural:turbulence:96x96x96:4", test::bricks8()));
  cpu::register_backend();
  RendererOptions o;
  o.backend = "cpu";
  o.backend_options.threads = 1;
  o.leaf_size = glm::uvec3(8);
  o.loader_threads = 2;
  o.visible_slots = 2;

  // The working set of the first view, from a renderer whose cache holds everything.
  std::mt19937 rng(20261124);
  Camera camera = test::oblique_camera();
  std::uint64_t working_set = 0;
  {
    Renderer probe(src, o);
    working_set =
        probe.render_until_converged(soak_scene(0, 1, camera), 200).last.stats.working_set_bricks;
  }
  ASSERT_GT(working_set, 64u);
  const std::uint64_t slot_bytes = src->hierarchy().layout().padded_voxels();  // u8
  o.device_cache_bytes = std::max<std::uint64_t>(working_set / 16, 4) * slot_bytes;
  const std::uint64_t volume_bytes =
      src->hierarchy().bricks_per_channel() * src->volume().channels * slot_bytes;
  o.host_cache_bytes = volume_bytes / 16;
  Renderer r(src, o);

  std::uniform_real_distribution<double> step(-0.08, 0.08);
  std::uint32_t ch_a = 0, ch_b = 1;
  std::uint64_t rss_warm = 0, rss_max = 0, uploads = 0, remaps = 0;
  for (int f = 1; f <= kFrames; ++f) {
    // A random walk of the eye on a shell around the box, looking at a wandering target.
    glm::dvec3 eye = camera.eye - glm::dvec3(0.5);
    eye += glm::dvec3(step(rng), step(rng), step(rng));
    eye = glm::normalize(eye) * std::clamp(glm::length(eye), 1.2, 3.0);
    camera.eye = eye + glm::dvec3(0.5);
    camera.target = glm::clamp(camera.target + 0.3 * glm::dvec3(step(rng), step(rng), step(rng)),
                               glm::dvec3(0.3), glm::dvec3(0.7));
    if (rng() % 40 == 0) {  // a remap: another pair of channels
      ch_a = std::uint32_t(rng() % 4);
      ch_b = (ch_a + 1 + std::uint32_t(rng() % 3)) % 4;
      ++remaps;
    }
    const FrameReport rep = r.render_frame(soak_scene(ch_a, ch_b, camera));
    ASSERT_TRUE(rep.failures.empty()) << "frame " << f;
    uploads += rep.stats.bricks_uploaded;
    if (f % 100 == 0) {
      ASSERT_EQ(test::check_renderer_state(r, nullptr, *src), "") << "frame " << f;
    }
    if (f == kWarmup) rss_warm = resident_bytes();
    if (f >= kWarmup) rss_max = std::max(rss_max, resident_bytes());
    if (f % 1000 == 0) {
      std::printf("soak: frame %d, resident %.2f MiB\n", f, double(resident_bytes()) / 1048576.0);
    }
  }
  const std::uint64_t rss_end = resident_bytes();
  std::printf(
      "soak: %d frames, working set %llu bricks, device cache %llu slots, %llu uploads, %llu "
      "remaps, resident memory %.1f MiB at frame %d, %.1f MiB max after, %.1f MiB at the end\n",
      kFrames, static_cast<unsigned long long>(working_set),
      static_cast<unsigned long long>(o.device_cache_bytes / slot_bytes),
      static_cast<unsigned long long>(uploads), static_cast<unsigned long long>(remaps),
      double(rss_warm) / 1048576.0, kWarmup, double(rss_max) / 1048576.0,
      double(rss_end) / 1048576.0);
  EXPECT_GT(uploads, std::uint64_t(kFrames));  // the small cache kept the loader busy
  // Flat: caches and request sets are bounded, so growth after the warm-up is allocator noise.
  EXPECT_LT(rss_max, rss_warm + (std::uint64_t(4) << 20));
}
