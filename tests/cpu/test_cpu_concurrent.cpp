// Two CPU backends in one process render at the same time (each render() builds its own kernel
// context; nothing is shared between backends): every frame equals the same frame rendered
// alone. Run it under the tsan preset to check for races.
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cpu_test_util.hpp"
#include "support/test_views.hpp"

namespace resoct::test {
namespace {

Scene scene_for(std::uint32_t k) {
  Camera c = oblique_camera();
  c.eye = {1.9 - 0.3 * k, 1.3, 2.1};
  Scene s = make_scene(48, c);
  s.channels = {make_channel(0,
                             {{0.0, {1, 1, 1, 0}},
                              {0.1, {1, 1, 1, 0}},
                              {0.2, {1, 0.8, 0.3, 0.1}},
                              {1.0, {0.2 * k, 0.2, 0.9, 0.6}}},
                             0, 15)};
  return s;
}

TEST(CpuConcurrency, TwoBackendsRenderAtTheSameTime) {
  ProceduralSource tubes("procedural:tubes:64x64x64", bricks8());
  ProceduralSource turbulence("procedural:turbulence:48x48x48", bricks8());
  ResidentScene a(tubes, {0});
  ResidentScene b(turbulence, {0});
  constexpr int kFrames = 6;
  // Each backend on two threads, so that both OpenMP teams run at once.
  cpu::CpuBackend ba(2), bb(2);
  a.upload(ba);
  b.upload(bb);
  // Alone first: the expected frames.
  std::vector<Image> alone_a, alone_b;
  for (int f = 0; f < kFrames; ++f) {
    FrameResult ra, rb;
    ba.render(a.tables(scene_for(std::uint32_t(f % 3))), ra);
    bb.render(b.tables(scene_for(std::uint32_t((f + 1) % 3))), rb);
    alone_a.push_back(ra.image);
    alone_b.push_back(rb.image);
  }
  // Then at the same time, each thread reusing its FrameResult (and so its image) across frames.
  std::vector<Image> together_a(kFrames), together_b(kFrames);
  auto run = [&](cpu::CpuBackend& backend, ResidentScene& rs, std::uint32_t shift,
                 std::vector<Image>& out) {
    FrameResult r;
    for (int f = 0; f < kFrames; ++f) {
      backend.render(rs.tables(scene_for(std::uint32_t((f + shift) % 3))), r);
      out[std::size_t(f)] = r.image;
    }
  };
  std::thread ta(run, std::ref(ba), std::ref(a), 0u, std::ref(together_a));
  std::thread tb(run, std::ref(bb), std::ref(b), 1u, std::ref(together_b));
  ta.join();
  tb.join();
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(together_a[std::size_t(f)].pixels(), alone_a[std::size_t(f)].pixels()) << f;
    EXPECT_EQ(together_b[std::size_t(f)].pixels(), alone_b[std::size_t(f)].pixels()) << f;
  }
}

}  // namespace
}  // namespace resoct::test
