// The scene's `timepoint` (docs/scene.md "Time series"): parsed, written only when non-zero,
// round-tripped, and validated against the source's timepoint count with the field named.
#include <gtest/gtest.h>

#include <string>

#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

std::string scene_text(const std::string& extra) {
  return R"({"camera": {"eye": [1.8, 0.9, 1.6], "target": [0.5, 0.5, 0.5]},
 "channels": [{"channel": 0, "tf": [[0.0, 0, 0, 0, 0], [1.0, 1, 1, 1, 0.8]]}])" +
         extra + "}";
}

TEST(SceneTimepoint, ParsesAndRoundTrips) {
  const Scene s = parse_scene(scene_text(R"(, "timepoint": 3)"));
  EXPECT_EQ(s.timepoint, 3u);
  EXPECT_EQ(parse_scene(scene_to_json(s)), s);
  EXPECT_NE(scene_to_json(s).find("\"timepoint\": 3"), std::string::npos);
  // Absent stays absent (the source's own timepoint) and is not written, so documents of
  // scenes without a series stay as they were; an explicit 0 is kept.
  const Scene absent = parse_scene(scene_text(""));
  EXPECT_FALSE(absent.timepoint.has_value());
  EXPECT_EQ(scene_to_json(absent).find("timepoint"), std::string::npos);
  EXPECT_EQ(parse_scene(scene_to_json(absent)), absent);
  const Scene zero = parse_scene(scene_text(R"(, "timepoint": 0)"));
  EXPECT_EQ(zero.timepoint, 0u);
  EXPECT_EQ(parse_scene(scene_to_json(zero)), zero);
}

TEST(SceneTimepoint, BadValuesNameTheField) {
  EXPECT_RESOCT_ERROR(parse_scene(scene_text(R"(, "timepoint": -1)"), "s.json"),
                      ErrorCode::invalid_argument, "s.json: timepoint:");
  EXPECT_RESOCT_ERROR(parse_scene(scene_text(R"(, "timepoint": 4294967296)"), "s.json"),
                      ErrorCode::invalid_argument, "s.json: timepoint:");
  EXPECT_RESOCT_ERROR(parse_scene(scene_text(R"(, "timepoint": 1.5)"), "s.json"),
                      ErrorCode::invalid_argument, "s.json: timepoint: must be an integer");
  EXPECT_RESOCT_ERROR(parse_scene(scene_text(R"(, "timepoint": "2")"), "s.json"),
                      ErrorCode::invalid_argument, "s.json: timepoint: must be an integer");
}

TEST(SceneTimepoint, ValidatesAgainstTheSourcesTimepoints) {
  Scene s = parse_scene(scene_text(R"(, "timepoint": 4)"));
  VolumeDesc v;
  v.extent = {8, 8, 8};
  EXPECT_NO_THROW(s.validate(v, 5, "scene"));
  EXPECT_RESOCT_ERROR(s.validate(v, 4, "scene"), ErrorCode::invalid_argument,
                      "scene: timepoint: 4 but the volume has 4 timepoints (0..3)");
  s.timepoint = 1;
  EXPECT_RESOCT_ERROR(s.validate(v, 1, "scene"), ErrorCode::invalid_argument,
                      "scene: timepoint: 1 but the volume has 1 timepoint (0..0)");
  s.timepoint.reset();  // absent: whatever the source reads
  EXPECT_NO_THROW(s.validate(v, 1, "scene"));
}

}  // namespace
