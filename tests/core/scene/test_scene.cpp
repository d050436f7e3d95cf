// Scene JSON: the documented example parses to the expected values, save/load round trips, and
// every invalid field is reported with its JSON path (files written to a temporary directory).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"

namespace {

using namespace resoct;
namespace fs = std::filesystem;

const char* kExample =
    R"({"camera": {"eye": [1.8, 0.9, 1.6], "target": [0.5, 0.5, 0.5], "up": [0, 1, 0], "fov_deg": 40, "projection": "perspective"},
 "channels": [{"channel": 0, "tf": [[0.0, 0, 0, 0, 0], [0.3, 1, 0.5, 0.2, 0.0], [1.0, 1, 1, 1, 0.8]], "levels": [0, 15], "importance": 0}],
 "step_scale": 1.0, "lod_error_px": 1.0, "ert_opacity": 0.99, "background": [0, 0, 0, 1], "effects": []})";

class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("resoct_test_scene_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& text, const std::string& name = "scene.json") {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  // The example with `from` replaced by `to` (which must occur exactly once).
  std::string variant(const std::string& from, const std::string& to) {
    std::string text = kExample;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from;
    text.replace(at, from.size(), to);
    return write(text);
  }
  fs::path dir_;
};

TEST_F(SceneFiles, ExampleParsesToExpectedValues) {
  const Scene s = load_scene(write(kExample));
  EXPECT_EQ(s.camera.eye, glm::dvec3(1.8, 0.9, 1.6));
  EXPECT_EQ(s.camera.target, glm::dvec3(0.5, 0.5, 0.5));
  EXPECT_EQ(s.camera.up, glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.camera.fov_deg, 40.0);
  EXPECT_EQ(s.camera.projection, Projection::perspective);
  EXPECT_EQ(s.viewport, Viewport{});
  ASSERT_EQ(s.channels.size(), 1u);
  const ChannelSettings& c = s.channels[0];
  EXPECT_EQ(c.channel, 0u);
  ASSERT_EQ(c.tf.points().size(), 3u);
  EXPECT_EQ(c.tf.points()[1].value, 0.3);
  EXPECT_EQ(c.tf.points()[1].rgba, glm::dvec4(1, 0.5, 0.2, 0.0));
  EXPECT_EQ(c.tf.points()[2].rgba, glm::dvec4(1, 1, 1, 0.8));
  EXPECT_EQ(c.finest_level, 0u);
  EXPECT_EQ(c.coarsest_level, 15u);
  EXPECT_EQ(c.importance, 0);
  EXPECT_EQ(s.step_scale, 1.0);
  EXPECT_EQ(s.lod_error_px, 1.0);
  EXPECT_EQ(s.ert_opacity, 0.99);
  EXPECT_EQ(s.background, glm::dvec4(0, 0, 0, 1));
  EXPECT_TRUE(s.effects.empty());
}

TEST_F(SceneFiles, SaveLoadRoundTrip) {
  Scene s = load_scene(write(kExample));
  s.camera.projection = Projection::orthographic;
  s.camera.ortho_height = 1.25;
  s.viewport = {320, 200};
  ChannelSettings extra;
  extra.channel = 7;
  extra.tf = TransferFunction({{0.1, {0.1, 0.2, 0.3, 0.4}}, {0.1, {1, 1, 1, 1}}});
  extra.finest_level = 2;
  extra.coarsest_level = 4;
  extra.importance = -3;
  s.channels.push_back(extra);
  s.step_scale = 0.1;
  s.lod_error_px = 2.5;
  s.lod_error_color = 0.03;
  s.ert_opacity = 1.0;
  s.background = {0.1, 0.2, 0.3, 0.4};
  s.effects = {Effect::shadows, Effect::shading};
  const std::string path = (dir_ / "saved.json").string();
  save_scene(s, path);
  EXPECT_EQ(load_scene(path), s);
  EXPECT_EQ(parse_scene(scene_to_json(s)), s);
  // Only the saved file exists (the temporary was renamed).
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 2);  // scene.json from write() and saved.json
}

TEST_F(SceneFiles, AcceptsOptionalFieldsAndDefaults) {
  const Scene s = load_scene(write(R"({
    "camera": {"eye": [0.5, 0.5, 3], "target": [0.5, 0.5, 0.5], "projection": "orthographic",
               "ortho_height": 2},
    "viewport": {"width": 64, "height": 32},
    "channels": [{"channel": 3, "tf": [[0.5, 1, 1, 1, 1]], "importance": 2, "mode": "dvr"}],
    "effects": ["shading", "shadows"]})"));
  EXPECT_EQ(s.camera.projection, Projection::orthographic);
  EXPECT_EQ(s.camera.ortho_height, 2.0);
  EXPECT_EQ(s.camera.up, glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.viewport, (Viewport{64, 32}));
  EXPECT_EQ(s.channels[0].channel, 3u);
  EXPECT_EQ(s.channels[0].importance, 2);
  EXPECT_EQ(s.channels[0].finest_level, 0u);
  EXPECT_EQ(s.channels[0].coarsest_level, 15u);
  EXPECT_EQ(s.step_scale, 1.0);
  EXPECT_EQ(s.ert_opacity, 0.99);
  EXPECT_EQ(s.effects, (std::vector<Effect>{Effect::shading, Effect::shadows}));
}

TEST_F(SceneFiles, InvalidFieldsNameTheirJsonPath) {
  struct Case {
    const char* from;
    const char* to;
    const char* needle;
  };
  const Case cases[] = {
      {R"("fov_deg": 40)", R"("fov_deg": 180)", "scene.json: camera.fov_deg: 180 outside (0, 180)"},
      {R"("fov_deg": 40)", R"("fov_deg": 0)", "camera.fov_deg"},
      {R"("fov_deg": 40)", R"("fov_deg": "wide")", "camera.fov_deg: must be a number"},
      {R"("perspective")", R"("fisheye")", "camera.projection: 'fisheye'"},
      {R"("eye": [1.8, 0.9, 1.6])", R"("eye": [1.8, 0.9])", "camera.eye: must have 3 numbers"},
      {R"("target": [0.5, 0.5, 0.5])", R"("target": [1.8, 0.9, 1.6])", "scene.json: camera:"},
      {R"([1.0, 1, 1, 1, 0.8])", R"([1.3, 1, 1, 1, 0.8])",
       "scene.json: channels[0].tf[2]: value 1.3 outside [0,1]"},
      {R"([0.3, 1, 0.5, 0.2, 0.0])", R"([0.0, 1, 0.5, 0.2, 0.0], [-0.1, 0, 0, 0, 0])",
       "channels[0].tf[2]: value -0.1 outside [0,1]"},
      {R"([1.0, 1, 1, 1, 0.8])", R"([0.2, 1, 1, 1, 0.8])",
       "channels[0].tf[2]: value 0.2 below the previous"},
      {R"([1.0, 1, 1, 1, 0.8])", R"([1.0, 1, 1, 1, 1.8])", "channels[0].tf[2]: alpha 1.8 outside"},
      {R"([1.0, 1, 1, 1, 0.8])", R"([1.0, 1, 1, 0.8])", "channels[0].tf[2]: must be [value"},
      {R"("levels": [0, 15])", R"("levels": [5, 3])",
       "channels[0].levels: finest 5 above coarsest 3"},
      {R"("levels": [0, 15])", R"("levels": [0, 40])",
       "channels[0].levels: levels must be in 0..31"},
      {R"("channel": 0)", R"("channel": 256)", "channels[0].channel: must be in 0..255"},
      {R"("channel": 0)", R"("channel": 1.5)", "channels[0].channel: must be an integer"},
      {R"("importance": 0)", R"("importance": 0, "mode": "xray")",
       "channels[0].mode: 'xray' is not a mode"},
      {R"("importance": 0)", R"("importance": 0, "colour": 1)", "channels[0].colour: unknown key"},
      {R"("step_scale": 1.0)", R"("step_scale": 0)", "scene.json: step_scale: 0 outside"},
      {R"("step_scale": 1.0)", R"("step_scale": -2)", "step_scale: -2 outside"},
      {R"("lod_error_px": 1.0)", R"("lod_error_px": 0)", "lod_error_px: 0 outside"},
      {R"("lod_error_px": 1.0)", R"("lod_error_px": 1.0, "lod_error_color": -0.1)",
       "lod_error_color: -0.1 outside [0, 1]"},
      {R"("lod_error_px": 1.0)", R"("lod_error_px": 1.0, "lod_error_color": 2)",
       "lod_error_color: 2 outside [0, 1]"},
      {R"("ert_opacity": 0.99)", R"("ert_opacity": 0)", "ert_opacity: 0 outside (0, 1]"},
      {R"("ert_opacity": 0.99)", R"("ert_opacity": 1.01)", "ert_opacity: 1.01 outside (0, 1]"},
      {R"("background": [0, 0, 0, 1])", R"("background": [0, 0, 2, 1])",
       "background[2]: 2 outside"},
      {R"("effects": [])", R"("effects": ["glow"])", "effects[0]: unknown effect 'glow'"},
      {R"("effects": [])", R"("effects": ["shading", "shading"])",
       "effects[1]: 'shading' is listed twice"},
      {R"("effects": [])", R"("effects": [], "ert": 1)", "scene.json: ert: unknown key"},
      {R"("up": [0, 1, 0], )", R"("up": [0, 1, 0], "zoom": 2, )", "camera.zoom: unknown key"},
  };
  for (const Case& c : cases) {
    const std::string path = variant(c.from, c.to);
    EXPECT_RESOCT_ERROR(load_scene(path), ErrorCode::invalid_argument, c.needle) << c.to;
  }
}

TEST_F(SceneFiles, MissingAndDuplicateFields) {
  EXPECT_RESOCT_ERROR(load_scene(write(R"({"channels": []})")), ErrorCode::invalid_argument,
                      "scene.json: camera: missing");
  EXPECT_RESOCT_ERROR(
      load_scene(write(R"({"camera": {"eye": [2, 0, 0], "target": [0, 0, 0]}, "channels": []})")),
      ErrorCode::invalid_argument, "channels: must list at least one channel");
  EXPECT_RESOCT_ERROR(load_scene(write(R"({"camera": {"eye": [2, 0, 0]}, "channels": []})")),
                      ErrorCode::invalid_argument, "camera.target: missing");
  EXPECT_RESOCT_ERROR(load_scene(write(R"({"camera": {"eye": [2, 0, 0], "target": [0, 0, 0]},
     "channels": [{"tf": [[0, 0, 0, 0, 0]]}]})")),
                      ErrorCode::invalid_argument, "channels[0].channel: missing");
  EXPECT_RESOCT_ERROR(load_scene(write(R"({"camera": {"eye": [2, 0, 0], "target": [0, 0, 0]},
     "channels": [{"channel": 1, "tf": [[0, 0, 0, 0, 0]]}, {"channel": 1, "tf": [[0, 0, 0, 0, 0]]}]})")),
                      ErrorCode::invalid_argument,
                      "channels[1].channel: channel 1 is listed twice");
  EXPECT_RESOCT_ERROR(load_scene(write(R"([1, 2])")), ErrorCode::invalid_argument,
                      "(root): must be an object");
}

TEST_F(SceneFiles, MalformedJsonGivesByteOffset) {
  // The stray '}' is at byte 13 (1-based position 14 in nlohmann's count).
  const std::string path = write(R"({"camera": 1}})");
  EXPECT_RESOCT_ERROR(load_scene(path), ErrorCode::corrupt,
                      "scene.json: offset 14: malformed JSON");
  EXPECT_RESOCT_ERROR(load_scene(write(R"({"camera": )")), ErrorCode::corrupt, "offset");
  EXPECT_RESOCT_ERROR(load_scene((dir_ / "absent.json").string()), ErrorCode::io, "absent.json");
}

TEST_F(SceneFiles, ValidateAgainstVolume) {
  const Scene s = load_scene(write(kExample));
  VolumeDesc v;
  v.channels = 1;
  EXPECT_NO_THROW(s.validate(v));
  Scene t = s;
  t.channels[0].channel = 3;
  EXPECT_RESOCT_ERROR(t.validate(v, "mine"), ErrorCode::invalid_argument,
                      "mine: channels[0].channel: channel 3 not in the volume's 1 channels");
  EXPECT_RESOCT_ERROR(save_scene(Scene{}, (dir_ / "empty.json").string()),
                      ErrorCode::invalid_argument, "channels");
  EXPECT_FALSE(fs::exists(dir_ / "empty.json"));
}

}  // namespace
