// Slices and the lens on Vulkan against the CPU oracle: the same kernel headers, so integer
// outputs (statistics, request keys and hits, used cache slots) must be identical and colours
// within kVulkanColourTolerance (1e-4), for slice scenes and lens scenes in all three render modes,
// warm and cold.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "resoct/sources/procedural_source.hpp"
#include "resoct/scene/scene.hpp"
#include "vulkan_test_util.hpp"
#include "support/vulkan_required.hpp"

namespace resoct::test {
namespace {

constexpr RenderMode kModes[] = {RenderMode::residency, RenderMode::pagetable, RenderMode::octree};

BrickLayout small_bricks() {
  BrickLayout l;
  l.brick_size = glm::uvec3(8);
  l.halo = 1;
  return l;
}

Scene base_scene(std::uint32_t size) {
  Scene s;
  s.camera.eye = {1.7, 1.2, 1.9};
  s.camera.target = {0.5, 0.5, 0.5};
  s.viewport = {size, size};
  s.step_scale = 0.5;
  ChannelSettings c;
  c.tf = TransferFunction(
      {{0.0, {1, 1, 1, 0}}, {0.2, {1, 0.5, 0.2, 0.02}}, {1.0, {0.2, 0.5, 1, 0.3}}});
  s.channels = {c};
  return s;
}

SlicePlane plane(glm::dvec3 p, glm::dvec3 n, bool window) {
  SlicePlane s;
  s.point = p;
  s.normal = n;
  s.channels = {0};
  if (window) {
    s.window = 0.8;
    s.level = 0.4;
  }
  return s;
}

Lens lens(bool coarse) {
  Lens l;
  l.center = {0.45, 0.55, 0.5};
  l.size = {0.35, 0.3, 0.4};
  const double c = std::cos(0.4), s = std::sin(0.4);
  l.axes = glm::dmat3(glm::dvec3(c, s, 0), glm::dvec3(-s, c, 0), glm::dvec3(0, 0, 1));
  if (coarse) {
    LensOutside o;
    o.channel = 0;
    o.hide = false;
    o.finest_level = 1;
    o.coarsest_level = 15;
    l.outside = {o};
  }
  return l;
}

struct Case {
  const char* name;
  Scene scene;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  Scene s = base_scene(32);
  s.slices = {plane({0.5, 0.5, 0.45}, {0.3, 0.2, 1.0}, true)};
  out.push_back({"one slice", s});
  s.slices = {plane({0.5, 0.5, 0.45}, {0, 0, 1}, true), plane({0.4, 0.5, 0.5}, {1, 0, 0}, false),
              plane({0.5, 0.62, 0.5}, {0.1, 1, 0.2}, true)};
  out.push_back({"three slices", s});
  s.channels[0].tf = TransferFunction({{0.0, {1, 1, 1, 0}}, {1.0, {1, 1, 1, 0}}});
  out.push_back({"slices only", s});
  s = base_scene(32);
  s.lens = lens(false);
  out.push_back({"lens hide", s});
  s.lens = lens(true);
  out.push_back({"lens coarser outside", s});
  s.slices = {plane({0.5, 0.5, 0.45}, {0.3, 0.2, 1.0}, true)};
  out.push_back({"lens and slice", s});
  return out;
}

void run_cases(const std::string& spec, const ResidentOptions& resident, RequestStrategy strategy,
               const char* label) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device");
  ProceduralSource src(spec, small_bricks());
  ResidentScene rs(src, {0}, resident);
  cpu::CpuBackend cpu(1);
  OracleDiff worst;
  for (const Case& c : cases()) {
    for (RenderMode mode : kModes) {
      FrameOptions o;
      o.mode = mode;
      o.request_strategy = strategy;
      const FrameResult a = render_on(cpu, rs, c.scene, o);
      const FrameResult b = render_on(*gpu, rs, c.scene, o);
      EXPECT_GT(a.stats.iterations + a.stats.samples, 0u) << c.name;
      expect_same_frame(a, b, std::string(label) + " " + c.name + " " + to_string(mode), worst);
    }
  }
  std::printf("[ vulkan ] slices/lens %-8s colour %.2e (x255 %.4f) stats %llu keys %zu used %zu\n",
              label, worst.colour, worst.colour * 255.0,
              static_cast<unsigned long long>(worst.stat_abs), worst.request_keys,
              worst.used_slots);
  expect_no_validation_messages(*gpu);
}

TEST(VulkanSlices, WarmCacheMatchesTheCpuBackend) {
  run_cases("procedural:sphere:32x32x32", ResidentOptions{}, RequestStrategy::global, "warm");
}

TEST(VulkanSlices, PartlyResidentGivesTheSameRequests) {
  ResidentOptions o;
  o.level_resident = [](std::uint32_t l) { return l >= 2; };
  run_cases("procedural:tubes:48x48x48", o, RequestStrategy::greedy, "partial");
}

// The shipped example scene (two slices and a lens with a coarser outside) as resoct-render
// renders it (tubes 64³, leaves 16³), with the lens and slices removed one at a time, and the
// plain scene as the control, at 64² pixels. Until the march took per-ray reciprocals
// (kernel/ray.glsl.h), the plain scene differed by one iteration on one ray: lavapipe lowers a
// division x / d to x * rcp(d), whose last bit can differ from the CPU's quotient, and one
// ray/box exit landed on the other side of a step boundary.
TEST(VulkanSlices, ShippedSlicesSceneMatchesTheCpuBackend) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device");
  ProceduralSource src("procedural:tubes:64x64x64", small_bricks());
  ResidentOptions ro;
  ro.leaf_size = glm::uvec3(16);
  ResidentScene rs(src, {0}, ro);
  Scene s = load_scene(std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/slices.json");
  s.viewport = {64, 64};
  cpu::CpuBackend cpu(1);
  OracleDiff d;
  FrameOptions o;
  o.start_depth = 2;
  expect_same_frame(render_on(cpu, rs, s, o), render_on(*gpu, rs, s, o), "slices.json", d);
  Scene no_lens = s;
  no_lens.lens.reset();
  expect_same_frame(render_on(cpu, rs, no_lens, o), render_on(*gpu, rs, no_lens, o), "no lens", d);
  Scene no_slices = s;
  no_slices.slices.clear();
  expect_same_frame(render_on(cpu, rs, no_slices, o), render_on(*gpu, rs, no_slices, o),
                    "no slices", d);
  Scene plain = no_slices;
  plain.lens.reset();
  expect_same_frame(render_on(cpu, rs, plain, o), render_on(*gpu, rs, plain, o), "plain", d);
  expect_no_validation_messages(*gpu);
}

}  // namespace
}  // namespace resoct::test
