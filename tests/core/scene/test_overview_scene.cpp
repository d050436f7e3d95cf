// overview_scene() shows the whole volume with its first channels visible; orbit() turns the
// camera about its target.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "resoct/scene/camera.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "support/expect_error.hpp"

namespace resoct::test {
namespace {

VolumeDesc volume(glm::u64vec3 extent, std::uint32_t channels, glm::dvec3 spacing = glm::dvec3(1)) {
  VolumeDesc v;
  v.extent = extent;
  v.channels = channels;
  v.spacing = spacing;
  return v;
}

// Every corner of the box projects inside the image.
void expect_box_in_view(const VolumeDesc& v, const Viewport& vp) {
  const Scene s = overview_scene(v, vp);
  const CameraRays rays(s.camera, s.viewport);
  const glm::dvec3 box = box_extent(v);
  const double tan_v = std::tan(s.camera.fov_deg * M_PI / 360.0);
  const double tan_h = tan_v * double(vp.width) / double(vp.height);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 p(c & 1 ? box.x : 0.0, c & 2 ? box.y : 0.0, c & 4 ? box.z : 0.0);
    const glm::dvec3 d = p - s.camera.eye;
    const double z = glm::dot(d, rays.forward());
    ASSERT_GT(z, 0.0);
    EXPECT_LE(std::abs(glm::dot(d, rays.right())) / z, tan_h) << "corner " << c;
    EXPECT_LE(std::abs(glm::dot(d, rays.up())) / z, tan_v) << "corner " << c;
  }
}

TEST(OverviewScene, TheWholeBoxIsInView) {
  expect_box_in_view(volume({128, 128, 128}, 1), {512, 512});
  expect_box_in_view(volume({512, 512, 16}, 3, {0.5, 0.5, 4.0}), {800, 300});
  expect_box_in_view(volume({64, 256, 32}, 2), {200, 600});
}

TEST(OverviewScene, FirstChannelsVisibleInColoursOfTheirOwn) {
  const VolumeDesc v = volume({64, 64, 64}, 6);
  const Scene s = overview_scene(v);
  ASSERT_EQ(s.channels.size(), std::size_t(kOverviewChannels));
  for (std::uint32_t c = 0; c < kOverviewChannels; ++c) {
    EXPECT_EQ(s.channels[c].channel, c);
    EXPECT_FALSE(s.channels[c].tf.fully_transparent());
    EXPECT_EQ(s.channels[c].tf.evaluate(0.0).a, 0.0);  // background values stay transparent
    EXPECT_GT(s.channels[c].tf.evaluate(1.0).a, 0.0);
    if (c > 0) {
      EXPECT_NE(s.channels[c].tf.evaluate(1.0), s.channels[0].tf.evaluate(1.0));
    }
  }
  EXPECT_NO_THROW(s.validate(v));
  EXPECT_EQ(overview_scene(volume({8, 8, 8}, 1)).channels.size(), 1u);
  EXPECT_RESOCT_ERROR(overview_scene(v, Viewport{0, 10}), ErrorCode::invalid_argument, "viewport");
}

// Hints from the data: a window (in the file's units) or histogram percentiles set the ramp, a
// colour replaces the palette's; without hints the overview is unchanged.
TEST(OverviewScene, TransferFunctionsFromHints) {
  VolumeDesc v = volume({32, 32, 32}, 3);
  v.type = VoxelType::u16;
  v.data_type = DataType::i16;  // stored = file + 32768
  v.ranges = {{32768.0 - 1000.0, 32768.0 + 3000.0}, {0.0, 100.0}, {0.0, 100.0}};
  OverviewHints h;
  h.channels.resize(3);
  h.channels[0].window = ValueRange{0.0, 2000.0};  // file units: 0.25 .. 0.75 of the range
  h.channels[0].colour = glm::dvec3(1.0, 0.5, 0.0);
  // Channel 1: 10 bins, half the values in bin 0, the rest spread over bins 4..8.
  h.channels[1].histogram = {500, 0, 0, 0, 100, 100, 100, 100, 100, 0};
  const Scene s = overview_scene(v, Viewport{64, 64}, h);
  ASSERT_EQ(s.channels.size(), 3u);
  const TransferFunction& w = s.channels[0].tf;
  EXPECT_EQ(w.evaluate(0.25).a, 0.0);
  EXPECT_GT(w.evaluate(0.26).a, 0.0);
  EXPECT_NEAR(w.evaluate(0.5).a, 0.25, 1e-12);
  EXPECT_EQ(w.evaluate(0.75), glm::dvec4(1.0, 0.5, 0.0, 0.5));
  EXPECT_EQ(w.evaluate(1.0), glm::dvec4(1.0, 0.5, 0.0, 0.5));
  // 50th percentile: the top of bin 0 (0.1); 99.5th: 95 % into bin 8 (0.895).
  const TransferFunction& p = s.channels[1].tf;
  EXPECT_EQ(p.evaluate(0.1).a, 0.0);
  EXPECT_GT(p.evaluate(0.11).a, 0.0);
  EXPECT_NEAR(p.evaluate(0.895).a, 0.5, 1e-12);
  EXPECT_NEAR(histogram_percentile(h.channels[1].histogram, 50.0).value(), 0.1, 1e-12);
  EXPECT_NEAR(histogram_percentile(h.channels[1].histogram, 99.5).value(), 0.895, 1e-12);
  EXPECT_FALSE(histogram_percentile({0, 0, 0}, 50.0).has_value());
  // Channel 2 has no hint: the default ramp, as without hints.
  EXPECT_EQ(s.channels[2].tf, overview_scene(v, Viewport{64, 64}).channels[2].tf);
  EXPECT_EQ(overview_scene(v, Viewport{64, 64}, {}), overview_scene(v, Viewport{64, 64}));
  // A window outside the range is ignored; a bad colour is an error naming "hints".
  OverviewHints outside;
  outside.channels.resize(1);
  outside.channels[0].window = ValueRange{5000.0, 6000.0};
  EXPECT_EQ(overview_scene(v, Viewport{64, 64}, outside).channels[0].tf,
            overview_scene(v, Viewport{64, 64}).channels[0].tf);
  OverviewHints bad;
  bad.channels.resize(1);
  bad.channels[0].colour = glm::dvec3(2.0, 0.0, 0.0);
  EXPECT_RESOCT_ERROR(overview_scene(v, Viewport{64, 64}, bad), ErrorCode::invalid_argument,
                      "hints");
}

TEST(Orbit, TurnsTheEyeAboutUpThroughTheTarget) {
  Camera c;
  c.eye = {1.5, 0.5, 0.5};
  c.target = {0.5, 0.5, 0.5};
  c.up = {0.0, 2.0, 0.0};
  const Camera quarter = orbit(c, 90.0);
  EXPECT_NEAR(quarter.eye.x, 0.5, 1e-12);
  EXPECT_NEAR(quarter.eye.y, 0.5, 1e-12);
  EXPECT_NEAR(quarter.eye.z, -0.5, 1e-12);  // +x turns to -z: counter-clockwise from above
  EXPECT_EQ(quarter.target, c.target);
  EXPECT_EQ(quarter.up, c.up);
  Camera around = c;
  for (int i = 0; i < 12; ++i) around = orbit(around, 30.0);
  EXPECT_NEAR(glm::length(around.eye - c.eye), 0.0, 1e-12);
  // A tilted eye keeps its height along up and its distance.
  c.eye = {1.2, 1.4, 0.9};
  const Camera turned = orbit(c, 47.0);
  EXPECT_NEAR(turned.eye.y, 1.4, 1e-12);
  EXPECT_NEAR(glm::length(turned.eye - c.target), glm::length(c.eye - c.target), 1e-12);
  c.up = glm::dvec3(0.0);
  EXPECT_RESOCT_ERROR(orbit(c, 10.0), ErrorCode::invalid_argument, "camera.up");
  EXPECT_RESOCT_ERROR(orbit(Camera{}, NAN), ErrorCode::invalid_argument, "degrees");
}

}  // namespace
}  // namespace resoct::test
