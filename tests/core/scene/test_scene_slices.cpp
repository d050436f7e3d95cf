// Scene JSON of slices and the lens: parsing into the documented values, exact round trip, and
// every invalid field reported with its JSON path.
#include <string>

#include <gtest/gtest.h>

#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"

namespace {

using namespace resoct;

const std::string kHead =
    R"({"camera": {"eye": [0.5, 0.5, 2.0], "target": [0.5, 0.5, 0.5]},
 "channels": [{"channel": 0, "tf": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 1]]},
              {"channel": 2, "tf": [[0, 0, 0, 0, 0], [1, 1, 0, 0, 1]]}])";

std::string scene_with(const std::string& extra) {
  return kHead + ", " + extra + "}";
}

const std::string kSlices =
    R"("slices": [{"point": [0.5, 0.25, 0.5], "normal": [0, 0, 2], "channels": [2],
                   "window": 0.5, "level": 0.25},
                  {"point": [0.1, 0.2, 0.3], "normal": [1, 1, 0], "channels": [0, 2]}])";
const std::string kLens =
    R"("lens": {"center": [0.4, 0.5, 0.6], "size": [0.2, 0.3, 0.4],
                "axes": [[0, 1, 0], [-1, 0, 0], [0, 0, 1]],
                "outside": [{"channel": 0, "levels": [2, 5]}, {"channel": 2, "hide": true}]})";

TEST(SceneSlices, ParsesDocumentedFields) {
  const Scene s = parse_scene(scene_with(kSlices + ", " + kLens));
  ASSERT_EQ(s.slices.size(), 2u);
  EXPECT_EQ(s.slices[0].point, glm::dvec3(0.5, 0.25, 0.5));
  EXPECT_EQ(s.slices[0].normal, glm::dvec3(0, 0, 2));
  EXPECT_EQ(s.slices[0].channels, std::vector<std::uint32_t>{2});
  ASSERT_TRUE(s.slices[0].window && s.slices[0].level);
  EXPECT_EQ(*s.slices[0].window, 0.5);
  EXPECT_EQ(*s.slices[0].level, 0.25);
  EXPECT_FALSE(s.slices[1].window.has_value());
  EXPECT_EQ(s.slices[1].channels, (std::vector<std::uint32_t>{0, 2}));
  ASSERT_TRUE(s.lens.has_value());
  EXPECT_EQ(s.lens->center, glm::dvec3(0.4, 0.5, 0.6));
  EXPECT_EQ(s.lens->size, glm::dvec3(0.2, 0.3, 0.4));
  EXPECT_EQ(s.lens->axes[0], glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.lens->axes[1], glm::dvec3(-1, 0, 0));
  ASSERT_EQ(s.lens->outside.size(), 2u);
  EXPECT_FALSE(s.lens->outside[0].hide);
  EXPECT_EQ(s.lens->outside[0].finest_level, 2u);
  EXPECT_EQ(s.lens->outside[0].coarsest_level, 5u);
  EXPECT_TRUE(s.lens->outside[1].hide);
}

TEST(SceneSlices, DefaultsAndRoundTrip) {
  const Scene plain = parse_scene(scene_with(R"("effects": [])"));
  EXPECT_TRUE(plain.slices.empty());
  EXPECT_FALSE(plain.lens.has_value());
  EXPECT_EQ(scene_to_json(plain).find("lens"), std::string::npos);

  const Scene lens_only = parse_scene(scene_with(R"("lens": {"center": [0.5, 0.5, 0.5],
                                                   "size": [0.1, 0.1, 0.1]})"));
  ASSERT_TRUE(lens_only.lens.has_value());
  EXPECT_EQ(lens_only.lens->axes, glm::dmat3(1.0));
  EXPECT_TRUE(lens_only.lens->outside.empty());  // every channel hidden outside

  const Scene s = parse_scene(scene_with(kSlices + ", " + kLens));
  EXPECT_EQ(parse_scene(scene_to_json(s)), s);
  EXPECT_EQ(parse_scene(scene_to_json(lens_only)), lens_only);
}

struct BadCase {
  const char* json;
  const char* needle;
};

TEST(SceneSlices, BadFieldsAreNamed) {
  const BadCase cases[] = {
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 0], "channels": [0]}])",
       "slices[0].normal: must not be zero"},
      {R"("slices": [{"point": [0.5, 0.5], "normal": [0, 0, 1], "channels": [0]}])",
       "slices[0].point: must have 3 numbers"},
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1], "channels": [1]}])",
       "slices[0].channels[0]: channel 1 is not one of the scene's channels"},
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1], "channels": []}])",
       "slices[0].channels: must list at least one channel"},
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1], "channels": [0, 0]}])",
       "slices[0].channels[1]: listed twice"},
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1], "channels": [0],
                      "window": 0, "level": 0.5}])",
       "slices[0].window: 0 must be a positive"},
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1], "channels": [0],
                      "window": 1}])",
       "slices[0].level: window and level go together"},
      {R"("slices": [{"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1], "channels": [0],
                      "colour": 1}])",
       "slices[0].colour: unknown key"},
      {R"("slices": [{"point": [0,0,0], "normal": [0,0,1], "channels": [0]},
                     {"point": [0,0,0], "normal": [0,0,1], "channels": [0]},
                     {"point": [0,0,0], "normal": [0,0,1], "channels": [0]},
                     {"point": [0,0,0], "normal": [0,0,1], "channels": [0]},
                     {"point": [0,0,0], "normal": [0,0,1], "channels": [0]}])",
       "slices: 5 planes, at most 4"},
      {R"("slices": {"point": [0.5, 0.5, 0.5]})", "slices: must be an array"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0, 0.1]})",
       "lens.size[1]: 0 must be positive"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, -1, 0.1]})",
       "lens.size[1]: -1 must be positive"},
      {R"("lens": {"size": [0.1, 0.1, 0.1]})", "lens.center: missing"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "axes": [[1, 0, 0], [0, 2, 0], [0, 0, 1]]})",
       "lens.axes[1]: must be a unit vector"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "axes": [[1, 0, 0], [0.6, 0.8, 0], [0, 0, 1]]})",
       "lens.axes[1]: not orthogonal to lens.axes[0]"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "axes": [[1, 0, 0], [0, 1, 0]]})",
       "lens.axes: must hold 3 axes"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "outside": [{"channel": 7}]})",
       "lens.outside[0].channel: channel 7 is not one of the scene's channels"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "outside": [{"channel": 0, "levels": [4, 2]}]})",
       "lens.outside[0].levels: finest 4 above coarsest 2"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "outside": [{"channel": 0, "levels": [0, 40]}]})",
       "lens.outside[0].levels: levels must be in 0..31"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "outside": [{"channel": 0, "hide": false}]})",
       "lens.outside[0].hide: false needs \"levels\""},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "outside": [{"channel": 0, "hide": true, "levels": [1, 2]}]})",
       "lens.outside[0].levels: a hidden channel takes no level range"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1],
                   "outside": [{"channel": 0}, {"channel": 0}]})",
       "lens.outside[1].channel: listed twice"},
      {R"("lens": {"center": [0.5, 0.5, 0.5], "size": [0.1, 0.1, 0.1], "shape": "box"})",
       "lens.shape: unknown key"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.json);
    EXPECT_RESOCT_ERROR(parse_scene(scene_with(c.json), "s.json"), ErrorCode::invalid_argument,
                        std::string("s.json: ") + c.needle);
  }
}

TEST(SceneSlices, ValidateChecksScenesBuiltInCode) {
  Scene s = parse_scene(scene_with(kSlices + ", " + kLens));
  s.slices[1].normal = glm::dvec3(0.0);
  EXPECT_RESOCT_ERROR(s.validate("code"), ErrorCode::invalid_argument,
                      "code: slices[1].normal: must not be zero");
  s = parse_scene(scene_with(kSlices + ", " + kLens));
  s.lens->axes[2] = glm::dvec3(0.0, 0.0, 0.5);
  EXPECT_RESOCT_ERROR(s.validate("code"), ErrorCode::invalid_argument,
                      "code: lens.axes[2]: must be a unit vector");
  s = parse_scene(scene_with(kSlices + ", " + kLens));
  s.channels.pop_back();  // channel 2 is still shown on slices and named by the lens
  EXPECT_RESOCT_ERROR(s.validate("code"), ErrorCode::invalid_argument,
                      "code: slices[0].channels[0]: channel 2 is not one of the scene's channels");
}

}  // namespace
