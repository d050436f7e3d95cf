// Scene JSON for effects (docs/scene.md "Effects"): channel modes, isovalues, light, gradient
// stencil and shadow LOD factor parse, validate with named fields, and round-trip exactly.
#include <string>

#include <gtest/gtest.h>

#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"

namespace resoct {
namespace {

const std::string kHead =
    R"({"camera": {"eye": [1.8, 0.9, 1.6], "target": [0.5, 0.5, 0.5]}, "channels": [)";

std::string with(const std::string& channels, const std::string& rest = "") {
  return kHead + channels + "]" + rest + "}";
}

const std::string kIso =
    R"({"channel": 0, "mode": "iso", "isovalues": [0.25, 0.5], "tf": [[0, 1, 1, 1, 1]]})";
const std::string kMip = R"({"channel": 1, "mode": "mip", "tf": [[0, 1, 1, 1, 1]]})";
const std::string kDvr = R"({"channel": 2, "tf": [[0, 1, 1, 1, 0.5]]})";

TEST(SceneEffects, ParsesModesLightAndOptions) {
  const Scene s = parse_scene(with(
      kIso + "," + kMip + "," + kDvr + R"(,{"channel": 3, "mode": "aip", "tf": [[0, 1, 1, 1, 1]]})",
      R"(, "effects": ["shading", "shadows"], "light": {"direction": [0, -1, 0],
           "ambient": 0.1, "shininess": 8}, "gradient": "forward", "shadow_lod_factor": 4)"));
  ASSERT_EQ(s.channels.size(), 4u);
  EXPECT_EQ(s.channels[0].mode, ChannelMode::iso);
  EXPECT_EQ(s.channels[0].isovalues, (std::vector<double>{0.25, 0.5}));
  EXPECT_EQ(s.channels[1].mode, ChannelMode::mip);
  EXPECT_EQ(s.channels[2].mode, ChannelMode::dvr);
  EXPECT_EQ(s.channels[3].mode, ChannelMode::aip);
  EXPECT_EQ(s.light.kind, Light::Kind::directional);
  EXPECT_EQ(s.light.vector, glm::dvec3(0, -1, 0));
  EXPECT_EQ(s.light.ambient, 0.1);
  EXPECT_EQ(s.light.diffuse, 0.75);
  EXPECT_EQ(s.light.shininess, 8.0);
  EXPECT_EQ(s.gradient, GradientStencil::forward);
  EXPECT_EQ(s.shadow_lod_factor, 4u);
  EXPECT_TRUE(s.needs_gradients());
  EXPECT_EQ(parse_scene(scene_to_json(s)), s);

  const Scene p = parse_scene(with(kDvr, R"(, "light": {"position": [2, 2, 2]})"));
  EXPECT_EQ(p.light.kind, Light::Kind::point);
  EXPECT_FALSE(p.needs_gradients());
  EXPECT_EQ(parse_scene(scene_to_json(p)), p);
  // Defaults: headlight, central differences, shadow LOD factor 2.
  const Scene d = parse_scene(with(kDvr));
  EXPECT_EQ(d.light.kind, Light::Kind::headlight);
  EXPECT_EQ(d.gradient, GradientStencil::central);
  EXPECT_EQ(d.shadow_lod_factor, 2u);
  EXPECT_EQ(parse_scene(scene_to_json(d)), d);
}

TEST(SceneEffects, InvalidFieldsAreNamed) {
  struct Case {
    std::string json;
    const char* needle;
  };
  const Case cases[] = {
      {with(R"({"channel": 0, "mode": "iso", "tf": [[0, 1, 1, 1, 1]]})"),
       "channels[0].isovalues: mode \"iso\" needs 1..4 isovalues"},
      {with(R"({"channel": 0, "mode": "iso", "isovalues": [0.1, 0.2, 0.3, 0.4, 0.5],
                "tf": [[0, 1, 1, 1, 1]]})"),
       "channels[0].isovalues: mode \"iso\" needs 1..4"},
      {with(R"({"channel": 0, "mode": "iso", "isovalues": [1.5], "tf": [[0, 1, 1, 1, 1]]})"),
       "channels[0].isovalues[0]: 1.5 outside the normalized range"},
      {with(R"({"channel": 0, "isovalues": [0.5], "tf": [[0, 1, 1, 1, 1]]})"),
       "channels[0].isovalues: only channels of mode \"iso\""},
      {with(R"({"channel": 0, "mode": "iso", "isovalues": ["a"], "tf": [[0, 1, 1, 1, 1]]})"),
       "channels[0].isovalues[0]: must be a number"},
      {with(kDvr, R"(, "effects": ["shadows"])"), "effects: \"shadows\" darkens shaded samples"},
      {with(kDvr, R"(, "light": {"direction": [1, 0, 0], "position": [0, 0, 0]})"),
       "light: give a direction or a position, not both"},
      {with(kDvr, R"(, "light": {"direction": [0, 0, 0]})"), "light.direction: must not be zero"},
      {with(kDvr, R"(, "light": {"colour": 1})"), "light.colour: unknown key"},
      {with(kDvr, R"(, "light": {"specular": -1})"), "light.specular: -1 outside [0, 10]"},
      {with(kDvr, R"(, "light": {"shininess": 0.5})"), "light.shininess: 0.5 outside [1, 1024]"},
      {with(kDvr, R"(, "gradient": "sobel")"), "gradient: 'sobel' is not"},
      {with(kDvr, R"(, "shadow_lod_factor": 3)"), "shadow_lod_factor: 3 is not a power of two"},
      {with(kDvr, R"(, "shadow_lod_factor": 32)"), "shadow_lod_factor: 32 is not a power"},
  };
  for (const Case& c : cases) {
    EXPECT_RESOCT_ERROR(parse_scene(c.json, "s.json"), ErrorCode::invalid_argument, c.needle)
        << c.json;
  }
  // Shadows with an iso channel (no "shading") are valid: iso surfaces are always lit.
  EXPECT_NO_THROW(parse_scene(with(kIso, R"(, "effects": ["shadows"])")));
}

}  // namespace
}  // namespace resoct
