// The Vulkan backend against the CPU backend (the oracle): the same resident state and tables
// must give the same requests, used slots and integer statistics, and colours within
// kVulkanColourTolerance (1e-4).
#include <cstdio>
#include <vector>

#include "vulkan_test_util.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/scene/scene.hpp"
#include "support/vulkan_required.hpp"

namespace resoct::test {
namespace {

constexpr std::uint32_t kSize = 32;

struct Case {
  const char* name;  // examples/scenes/<name>.json
  const char* spec;  // a small instance of the dataset
};

const Case kCases[] = {
    {"tubes", "procedural:tubes:32x32x32"},
    {"noisefloor", "procedural:noisefloor:32x32x32"},
    {"turbulence", "procedural:turbulence:32x32x32"},
    {"mandelbulb", "procedural:mandelbulb:32x32x32"},
    {"cells", "procedural:cells:64x64x16:16"},
    {"constant", "procedural:constant:24x24x24"},
    {"ramp", "procedural:ramp:32x32x32"},
    {"sphere", "procedural:sphere:32x32x32"},
};

constexpr RenderMode kModes[] = {RenderMode::residency, RenderMode::pagetable, RenderMode::octree};

BrickLayout small_bricks() {
  BrickLayout l;
  l.brick_size = glm::uvec3(8);
  l.halo = 1;
  return l;
}

Scene shipped_scene(const std::string& name) {
  Scene s = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/" + name + ".json");
  s.viewport = Viewport{kSize, kSize};
  return s;
}

std::vector<std::uint32_t> scene_channels(const Scene& s) {
  std::vector<std::uint32_t> c;
  for (const auto& ch : s.channels) c.push_back(ch.channel);
  return c;
}

OracleDiff g_worst;

void compare_all_modes(vk::VulkanBackend& gpu, const ResidentScene& rs, const Scene& scene,
                       const std::string& what, RequestStrategy strategy) {
  cpu::CpuBackend cpu(1);
  OracleDiff d;
  for (RenderMode mode : kModes) {
    FrameOptions o;
    o.mode = mode;
    o.request_strategy = strategy;
    const FrameResult a = render_on(cpu, rs, scene, o);
    const FrameResult b = render_on(gpu, rs, scene, o);
    EXPECT_GT(a.stats.iterations, 0u) << what;
    expect_same_frame(a, b, what + " " + to_string(mode), d);
  }
  g_worst.colour = std::max(g_worst.colour, d.colour);
  g_worst.stat_abs = std::max(g_worst.stat_abs, d.stat_abs);
  g_worst.request_keys = std::max(g_worst.request_keys, d.request_keys);
  g_worst.request_hits = std::max(g_worst.request_hits, d.request_hits);
  g_worst.used_slots = std::max(g_worst.used_slots, d.used_slots);
  std::printf("[ vulkan ] %-44s colour %.2e (x255 %.4f) stats %llu keys %zu hits %llu used %zu\n",
              what.c_str(), d.colour, d.colour * 255.0, static_cast<unsigned long long>(d.stat_abs),
              d.request_keys, static_cast<unsigned long long>(d.request_hits), d.used_slots);
}

TEST(VulkanOracle, ShippedScenesAllModesMatchTheCpuBackend) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  for (const Case& c : kCases) {
    ProceduralSource src(c.spec, small_bricks());
    const Scene scene = shipped_scene(c.name);
    ResidentScene rs(src, scene_channels(scene));
    compare_all_modes(*gpu, rs, scene, c.name, RequestStrategy::global);
  }
  RecordProperty("max_colour_difference_x255", std::to_string(g_worst.colour * 255.0));
  expect_no_validation_messages(*gpu);
}

// Pre-integrated transfer functions (kernel/preintegration.glsl.h, the plain pipeline variant
// with RESOCT_EFFECT_PREINT) at coarse steps, where segments span many LUT bins.
TEST(VulkanOracle, PreintegratedScenesAllModesMatchTheCpuBackend) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  for (const Case& c : {kCases[0], kCases[2], kCases[4]}) {
    ProceduralSource src(c.spec, small_bricks());
    Scene scene = shipped_scene(c.name);
    scene.preintegration = true;
    scene.step_scale = 2.0;
    ResidentScene rs(src, scene_channels(scene));
    compare_all_modes(*gpu, rs, scene, std::string(c.name) + " preint", RequestStrategy::global);
  }
  expect_no_validation_messages(*gpu);
}

TEST(VulkanOracle, MissingFineLevelsGiveTheSameRequests) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  // All u8: every distinct voxel type costs a pipeline compile (seconds on lavapipe); the
  // shipped-scene test covers u16 and f32.
  for (const char* name : {"turbulence", "noisefloor", "tubes"}) {
    const Case* c = nullptr;
    for (const Case& k : kCases) {
      if (std::string(k.name) == name) c = &k;
    }
    ASSERT_NE(c, nullptr);
    ProceduralSource src(c->spec, small_bricks());
    const Scene scene = shipped_scene(name);
    ResidentOptions ro;
    // Only the coarse levels are resident and no metadata below them: every fine sample misses.
    ro.level_resident = [](std::uint32_t level) { return level >= 2; };
    ResidentScene rs(src, scene_channels(scene), ro);
    for (RequestStrategy s : {RequestStrategy::global, RequestStrategy::greedy}) {
      cpu::CpuBackend cpu(1);
      FrameOptions o;
      o.request_strategy = s;
      const FrameResult a = render_on(cpu, rs, scene, o);
      EXPECT_FALSE(a.brick_requests.empty()) << name;
      compare_all_modes(*gpu, rs, scene, std::string(name) + " coarse-only", s);
    }
  }
  expect_no_validation_messages(*gpu);
}

TEST(VulkanOracle, PartialBricksAndU16AndF32Types) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  // A checkerboard of missing level-0 bricks over datasets of each voxel type.
  for (const char* spec : {"procedural:noisefloor:40x24x32", "procedural:cells:48x40x12:16",
                           "procedural:ramp:20x36x28"}) {
    ProceduralSource src(spec, small_bricks());
    Scene scene =
        shipped_scene(std::string(spec).find("cells") != std::string::npos  ? "cells"
                      : std::string(spec).find("ramp") != std::string::npos ? "ramp"
                                                                            : "noisefloor");
    ResidentOptions ro;
    ro.brick_resident = [](std::uint32_t level, glm::uvec3 b) {
      return level > 0 || ((b.x + b.y + b.z) % 2) == 0;
    };
    ResidentScene rs(src, scene_channels(scene), ro);
    compare_all_modes(*gpu, rs, scene, std::string(spec) + " checkerboard",
                      RequestStrategy::greedy);
  }
  // The same data with the cache split over several buffers of 5 bricks (10^3 voxels) each
  // (one dataset: each chunk count is another pipeline compile).
  for (const char* spec : {"procedural:ramp:20x36x28"}) {
    ProceduralSource src(spec, small_bricks());
    const bool ramp = std::string(spec).find("ramp") != std::string::npos;
    const Scene scene = shipped_scene(ramp ? "ramp" : "noisefloor");
    ResidentOptions ro;
    ro.level_resident = [](std::uint32_t level) { return level >= 1; };
    ResidentScene rs(src, scene_channels(scene), ro);
    gpu->debug_limit_cache_buffer(5u * 1000u * (ramp ? 4u : 1u));
    compare_all_modes(*gpu, rs, scene, std::string(spec) + " split cache", RequestStrategy::global);
    gpu->debug_limit_cache_buffer(0);
  }
  expect_no_validation_messages(*gpu);
}

}  // namespace
}  // namespace resoct::test
