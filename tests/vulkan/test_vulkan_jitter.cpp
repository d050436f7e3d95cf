// Jittered frames on the Vulkan backend against the CPU backend (the oracle, as
// test_vulkan_oracle.cpp): the same tables with a sub-pixel offset and a sample shift must give
// the same requests, slots and statistics, and colours within kVulkanColourTolerance; a zero
// jitter gives the plain frame bit for bit on the device too.
#include <cstdio>
#include <vector>

#include "resoct/scene/scene.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/vulkan_required.hpp"
#include "vulkan_test_util.hpp"

namespace resoct::test {
namespace {

Scene shipped_scene(const std::string& name) {
  Scene s = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/" + name + ".json");
  s.viewport = Viewport{32, 32};
  return s;
}

std::vector<std::uint32_t> scene_channels(const Scene& s) {
  std::vector<std::uint32_t> c;
  for (const auto& ch : s.channels) c.push_back(ch.channel);
  return c;
}

TEST(VulkanJitter, JitteredFramesMatchTheCpuBackend) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  BrickLayout bricks;
  bricks.brick_size = glm::uvec3(8);
  bricks.halo = 1;
  OracleDiff d;
  for (const char* name : {"turbulence", "tubes"}) {
    ProceduralSource src(std::string("procedural:") + name + ":32x32x32", bricks);
    const Scene scene = shipped_scene(name);
    ResidentScene rs(src, scene_channels(scene));
    cpu::CpuBackend cpu(1);
    for (std::uint32_t i : {0u, 1u, 2u, 7u}) {
      FrameOptions o;
      o.jitter = halton_jitter(i);
      const FrameResult a = render_on(cpu, rs, scene, o);
      const FrameResult b = render_on(*gpu, rs, scene, o);
      EXPECT_GT(a.stats.iterations, 0u);
      expect_same_frame(a, b, std::string(name) + " jitter " + std::to_string(i), d);
      if (i == 0) {
        // Zero jitter: the device's frame is the one it renders without any.
        const FrameResult plain = render_on(*gpu, rs, scene, FrameOptions{});
        EXPECT_EQ(plain.image, b.image) << name;
      }
    }
  }
  std::printf("[ vulkan ] jittered frames: colour %.2e (x255 %.4f) stats %llu keys %zu\n", d.colour,
              d.colour * 255.0, static_cast<unsigned long long>(d.stat_abs), d.request_keys);
  expect_no_validation_messages(*gpu);
}

}  // namespace
}  // namespace resoct::test
