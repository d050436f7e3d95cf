// Effects on the Vulkan backend against the CPU oracle: every effect specialization (shading,
// shadows, isosurfaces, MIP, AIP, mixed) must give the CPU's integer outputs (statistics
// including gradient evaluations and shadow rays, requests, used slots) and colours within
// kVulkanColourTolerance (1e-4), with no validation message; each effect mask compiles one pipeline
// variant, reused.
#include <cstdio>
#include <string>
#include <vector>

#include "vulkan_test_util.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/scene/scene.hpp"
#include "support/vulkan_required.hpp"

namespace resoct::test {
namespace {

ChannelSettings channel(std::uint32_t c, ChannelMode mode, std::vector<double> iso = {}) {
  ChannelSettings s;
  s.channel = c;
  s.tf = TransferFunction(
      {{0.0, {0.1, 0.3, 1.0, 0.0}}, {0.25, {1.0, 0.6, 0.2, 0.05}}, {1.0, {1.0, 1.0, 1.0, 0.4}}});
  s.mode = mode;
  s.isovalues = std::move(iso);
  return s;
}

Scene base_scene() {
  Scene s;
  s.camera.eye = {1.9, 1.3, 2.1};
  s.camera.target = {0.5, 0.5, 0.5};
  s.camera.fov_deg = 35.0;
  s.viewport = {32, 32};
  s.step_scale = 0.5;
  return s;
}

struct EffectCase {
  const char* name;
  Scene scene;
};

// Every scene uses all four effect bits, so the test compiles one pipeline (lavapipe needs tens
// of seconds per kernel variant) that contains all effect code; the scenes differ in what they
// exercise: channel modes (iso + shaded DVR + MIP, then AIP), light kinds, stencils, shadow LOD.
std::vector<EffectCase> cases() {
  std::vector<EffectCase> out;
  Scene s = base_scene();
  s.channels = {channel(0, ChannelMode::iso, {0.3, 0.6}), channel(1, ChannelMode::dvr),
                channel(2, ChannelMode::mip)};
  s.effects = {Effect::shading, Effect::shadows};
  s.light.kind = Light::Kind::directional;
  s.light.vector = {-1.0, -0.5, -0.25};
  out.push_back({"iso+dvr+mip, directional", s});
  s.channels = {channel(0, ChannelMode::iso, {0.5}), channel(1, ChannelMode::aip),
                channel(2, ChannelMode::dvr)};
  s.light.kind = Light::Kind::point;
  s.light.vector = {1.5, 1.5, 1.5};
  s.gradient = GradientStencil::forward;
  s.shadow_lod_factor = 4;
  out.push_back({"iso+aip+dvr, point, forward, shadow x4", s});
  s.light.kind = Light::Kind::headlight;
  s.gradient = GradientStencil::central;
  s.shadow_lod_factor = 1;
  out.push_back({"headlight, shadow x1", s});
  return out;
}

TEST(VulkanEffects, EverySpecializationMatchesTheCpuOracle) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  // Three channels of curved tubes crossing brick borders.
  ProceduralSource src("procedural:tubes:32x32x32:3", BrickLayout{glm::uvec3(8), 1});
  OracleDiff worst;
  for (const EffectCase& c : cases()) {
    std::vector<std::uint32_t> chans;
    for (const auto& ch : c.scene.channels) chans.push_back(ch.channel);
    ResidentScene rs(src, chans);
    for (RenderMode mode : {RenderMode::residency, RenderMode::pagetable}) {
      FrameOptions o;
      o.mode = mode;
      cpu::CpuBackend cpu(1);
      const FrameResult a = render_on(cpu, rs, c.scene, o);
      const FrameResult b = render_on(*gpu, rs, c.scene, o);
      const std::string what = std::string(c.name) + " " + to_string(mode);
      expect_same_frame(a, b, what, worst);
      EXPECT_EQ(a.stats.gradient_evals, b.stats.gradient_evals) << what;
      EXPECT_EQ(a.stats.shadow_rays, b.stats.shadow_rays) << what;
    }
  }
  // One effect mask in use: one pipeline, reused by every scene and mode.
  const std::size_t pipelines = gpu->debug_pipeline_count();
  EXPECT_EQ(pipelines, 1u);
  std::printf("effects oracle: max colour diff %.2e, %zu pipelines\n", worst.colour, pipelines);
  expect_no_validation_messages(*gpu);
}

// Effects with pre-integrated DVR channels: shading multiplies the pre-integrated colour, iso
// and MIP channels ignore it.
TEST(VulkanEffects, PreintegrationWithEffectsMatchesTheCpuOracle) {
  auto gpu = make_validated_vulkan();
  if (!gpu) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
  ProceduralSource src("procedural:tubes:32x32x32:3", BrickLayout{glm::uvec3(8), 1});
  OracleDiff worst;
  // Shading, an iso and a MIP channel, no shadows (mask 29: a smaller pipeline than all bits,
  // lavapipe compiles and runs it within the frame timeout on a loaded machine).
  Scene s = base_scene();
  s.viewport = {24, 24};
  s.channels = {channel(0, ChannelMode::iso, {0.3, 0.6}), channel(1, ChannelMode::dvr),
                channel(2, ChannelMode::mip)};
  s.effects = {Effect::shading};
  s.preintegration = true;
  s.step_scale = 1.5;
  std::vector<std::uint32_t> chans;
  for (const auto& ch : s.channels) chans.push_back(ch.channel);
  ResidentScene rs(src, chans);
  for (RenderMode mode : {RenderMode::residency, RenderMode::pagetable}) {
    FrameOptions o;
    o.mode = mode;
    cpu::CpuBackend cpu(1);
    const FrameResult a = render_on(cpu, rs, s, o);
    const FrameResult b = render_on(*gpu, rs, s, o);
    const std::string what = std::string("preint ") + to_string(mode);
    expect_same_frame(a, b, what, worst);
    EXPECT_EQ(a.stats.gradient_evals, b.stats.gradient_evals) << what;
    EXPECT_EQ(a.stats.shadow_rays, b.stats.shadow_rays) << what;
  }
  std::printf("preint effects oracle: max colour diff %.2e\n", worst.colour);
  expect_no_validation_messages(*gpu);
}

}  // namespace
}  // namespace resoct::test
