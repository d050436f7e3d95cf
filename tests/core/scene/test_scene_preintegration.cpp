// Scene JSON "preintegration" (docs/scene.md): parses, defaults to off, rejects non-booleans
// naming the field, round-trips; the frame tables carry the effect bit and one table per slot
// exactly when it is on.
#include <string>

#include <gtest/gtest.h>

#include "resoct/render/frame_tables.hpp"
#include "resoct/kernel/effects.glsl.h"
#include "resoct/scene/preintegration.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"
#include "support/resident_scene.hpp"

namespace resoct {
namespace {

const std::string kHead =
    R"({"camera": {"eye": [1.8, 0.9, 1.6], "target": [0.5, 0.5, 0.5]}, "channels": [)"
    R"({"channel": 0, "tf": [[0, 1, 1, 1, 0], [1, 1, 0.5, 0, 0.5]]}])";

TEST(ScenePreintegration, ParsesDefaultsAndRoundTrips) {
  EXPECT_FALSE(parse_scene(kHead + "}").preintegration);
  const Scene on = parse_scene(kHead + R"(, "preintegration": true})");
  EXPECT_TRUE(on.preintegration);
  EXPECT_FALSE(parse_scene(kHead + R"(, "preintegration": false})").preintegration);
  EXPECT_EQ(parse_scene(scene_to_json(on)), on);
}

TEST(ScenePreintegration, RejectsNonBooleansNamingTheField) {
  for (const char* bad : {"1", "\"yes\"", "null", "[true]"}) {
    EXPECT_RESOCT_ERROR(parse_scene(kHead + R"(, "preintegration": )" + bad + "}", "s.json"),
                        ErrorCode::invalid_argument,
                        "s.json: preintegration: must be true or false");
  }
  EXPECT_RESOCT_ERROR(parse_scene(kHead + R"(, "preintegrate": true})", "s.json"),
                      ErrorCode::invalid_argument, "preintegrate: unknown key");
}

TEST(ScenePreintegration, FrameTablesCarryTheBitAndOneTablePerSlot) {
  ProceduralSource src("procedural:tubes:16x16x16:2");
  test::ResidentScene rs(src, {0, 1});
  Scene s = parse_scene(kHead + "}");
  ChannelSettings second = s.channels[0];
  second.channel = 1;
  second.tf = TransferFunction({{0.0, {0, 0, 1, 0.2}}, {1.0, {1, 0, 0, 1.0}}});
  s.channels.push_back(second);
  const FrameTables off = rs.tables(s);
  EXPECT_EQ(off.fx.effects & kernel::RESOCT_EFFECT_PREINT, 0u);
  EXPECT_TRUE(off.preint_tables.empty());
  s.preintegration = true;
  const FrameTables on = rs.tables(s);
  EXPECT_NE(on.fx.effects & kernel::RESOCT_EFFECT_PREINT, 0u);
  ASSERT_EQ(on.preint_tables.size(), std::size_t(on.frame.page_slot_count) * 2 * kTfLutSize);
  for (std::uint32_t slot = 0; slot < 2; ++slot) {
    const std::vector<glm::vec4> lut(on.tf_luts.begin() + slot * kTfLutSize,
                                     on.tf_luts.begin() + (slot + 1) * kTfLutSize);
    const std::vector<glm::vec4> want = preintegration_table(lut);
    EXPECT_TRUE(
        std::equal(want.begin(), want.end(), on.preint_tables.begin() + slot * 2 * kTfLutSize))
        << slot;
  }
  // The other effect bits are unchanged by the switch.
  EXPECT_EQ(on.fx.effects & ~kernel::RESOCT_EFFECT_PREINT, off.fx.effects);
}

}  // namespace
}  // namespace resoct
