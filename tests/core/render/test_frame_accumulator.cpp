// FrameAccumulator and the jitter sequence (docs/rendering.md "Jittered accumulation"): the
// Halton offsets, the average, and the restarts on a changed scene or resident set.
#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "resoct/render/frame_accumulator.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

Scene small_scene() {
  Scene s;
  s.viewport = Viewport{3, 2};
  return s;
}

Image filled(float v) {
  return Image(3, 2, glm::vec4(v, v / 2.0f, 0.0f, 1.0f));
}

TEST(FrameJitter, HaltonSequenceStartsUnjitteredAndStaysInRange) {
  EXPECT_TRUE(halton_jitter(0).none());
  EXPECT_DOUBLE_EQ(halton(1, 2), 0.5);
  EXPECT_DOUBLE_EQ(halton(2, 2), 0.25);
  EXPECT_DOUBLE_EQ(halton(3, 2), 0.75);
  EXPECT_DOUBLE_EQ(halton(1, 3), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(halton(5, 3), 2.0 / 3.0 + 1.0 / 9.0);
  EXPECT_DOUBLE_EQ(halton(6, 5), 1.0 / 5.0 + 1.0 / 25.0);
  std::set<std::pair<float, float>> seen;
  for (std::uint32_t i = 1; i < 4096; ++i) {
    const FrameJitter j = halton_jitter(i);
    EXPECT_NO_THROW(j.validate()) << i;
    seen.insert({j.pixel_x, j.pixel_y});
  }
  EXPECT_EQ(seen.size(), 4095u);  // no sub-pixel position repeats
  // Low discrepancy: each quarter of the pixel receives a quarter of the first 64 offsets +- 2.
  int quarter[4] = {0, 0, 0, 0};
  for (std::uint32_t i = 1; i <= 64; ++i) {
    const FrameJitter j = halton_jitter(i);
    ++quarter[(j.pixel_x >= 0.0f ? 1 : 0) + (j.pixel_y >= 0.0f ? 2 : 0)];
  }
  for (int q : quarter) EXPECT_NEAR(q, 16, 2);
}

TEST(FrameJitter, OutOfRangeValuesAreRejectedNamingTheField) {
  EXPECT_RESOCT_ERROR((FrameJitter{0.5f, 0.0f, 0.0f}.validate()), ErrorCode::invalid_argument,
                      "jitter.pixel_x");
  EXPECT_RESOCT_ERROR((FrameJitter{0.0f, -0.5001f, 0.0f}.validate()), ErrorCode::invalid_argument,
                      "jitter.pixel_y");
  EXPECT_RESOCT_ERROR((FrameJitter{0.0f, 0.0f, INFINITY}.validate()), ErrorCode::invalid_argument,
                      "jitter.sample");
  EXPECT_NO_THROW((FrameJitter{-0.5f, 0.49f, -0.5f}.validate()));
}

TEST(FrameAccumulator, AveragesFramesAndOneFrameIsItselfBitForBit) {
  FrameAccumulator acc(3);
  const Scene s = small_scene();
  EXPECT_TRUE(acc.next(s).none());
  const Image first = Image(3, 2, glm::vec4(0.1f, 0.7f, 0.3f, 0.9f));
  acc.add(first, false);
  EXPECT_EQ(acc.image(), first);
  EXPECT_FALSE(acc.next(s).none());
  acc.add(filled(0.5f), false);
  EXPECT_EQ(acc.frames(), 2u);
  EXPECT_FALSE(acc.done());
  acc.next(s);
  acc.add(filled(0.25f), false);
  EXPECT_TRUE(acc.done());
  EXPECT_FLOAT_EQ(acc.image().at(2, 1).x, (0.1f + 0.5f + 0.25f) / 3.0f);
  EXPECT_FLOAT_EQ(acc.image().at(0, 0).y, (0.7f + 0.25f + 0.125f) / 3.0f);
}

TEST(FrameAccumulator, RestartsOnACameraChangeAndOnNewBricks) {
  FrameAccumulator acc(8);
  Scene s = small_scene();
  for (int i = 0; i < 3; ++i) {
    acc.next(s);
    acc.add(filled(0.5f), false);
  }
  EXPECT_EQ(acc.frames(), 3u);
  // A camera change: the average and the jitter sequence start again, unjittered.
  s.camera = orbit(s.camera, 1.0);
  EXPECT_TRUE(acc.next(s).none());
  EXPECT_EQ(acc.frames(), 0u);
  acc.add(filled(0.125f), false);
  EXPECT_EQ(acc.frames(), 1u);
  EXPECT_EQ(acc.image(), filled(0.125f));
  // Any other scene field counts too.
  acc.next(s);
  acc.add(filled(0.5f), false);
  s.step_scale = 2.0;
  acc.next(s);
  EXPECT_EQ(acc.frames(), 0u);
  acc.add(filled(0.5f), false);
  acc.next(s);
  acc.add(filled(0.5f), false);
  EXPECT_EQ(acc.frames(), 2u);
  // A frame that uploaded bricks starts the average with itself; the jitter goes on.
  const FrameJitter before = acc.next(s);
  acc.add(filled(0.75f), true);
  EXPECT_EQ(acc.frames(), 1u);
  EXPECT_EQ(acc.image(), filled(0.75f));
  EXPECT_NE(acc.next(s), before);
}

TEST(FrameAccumulator, BadInputIsRejectedNamingIt) {
  EXPECT_RESOCT_ERROR(FrameAccumulator(0), ErrorCode::invalid_argument, "max_frames");
  FrameAccumulator acc(4);
  EXPECT_RESOCT_ERROR(acc.add(filled(0.5f), false), ErrorCode::invalid_argument, "scene");
  acc.next(small_scene());
  EXPECT_RESOCT_ERROR(acc.add(Image(4, 4), false), ErrorCode::invalid_argument, "report");
  FrameReport device_only;  // output device on a device backend: no host pixels
  EXPECT_RESOCT_ERROR(acc.add(device_only), ErrorCode::invalid_argument, "report");
}

}  // namespace
}  // namespace resoct::test
