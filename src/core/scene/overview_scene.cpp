#include "resoct/scene/overview_scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

// Colours that stay apart when channels overlap additively: the usual fluorescence pseudo-colours
// (a single channel gets a warm white, which reads as density rather than as a label).
constexpr glm::dvec3 kSingleChannel{1.0, 0.85, 0.6};
constexpr glm::dvec3 kChannelColours[kOverviewChannels] = {
    {0.2, 1.0, 0.2}, {1.0, 0.2, 1.0}, {0.2, 0.8, 1.0}, {1.0, 0.8, 0.1}};

TransferFunction ramp(const glm::dvec3& c) {
  return TransferFunction({TfPoint{0.0, glm::dvec4(c, 0.0)}, TfPoint{0.1, glm::dvec4(c, 0.0)},
                           TfPoint{1.0, glm::dvec4(c, 0.5)}});
}

}  // namespace

Scene overview_scene(const VolumeDesc& volume, const Viewport& viewport) {
  volume.validate("volume");
  if (viewport.width == 0 || viewport.height == 0 || viewport.width > 16384 ||
      viewport.height > 16384) {
    throw invalid_parameter("viewport", "width and height must be in 1..16384");
  }
  Scene s;
  s.viewport = viewport;
  const glm::dvec3 box = box_extent(volume);
  s.camera.target = box * 0.5;
  s.camera.up = {0.0, 1.0, 0.0};
  s.camera.fov_deg = 40.0;
  // The bounding sphere fits the narrower of the two fields of view.
  const double aspect = double(viewport.width) / double(viewport.height);
  const double half_fov = s.camera.fov_deg * std::numbers::pi / 360.0;
  const double half_narrow = aspect < 1.0 ? std::atan(std::tan(half_fov) * aspect) : half_fov;
  const double distance = glm::length(box) / 2.0 / std::sin(half_narrow);
  s.camera.eye = s.camera.target + glm::normalize(glm::dvec3(1.0)) * distance;
  const std::uint32_t shown = std::min(volume.channels, kOverviewChannels);
  for (std::uint32_t c = 0; c < shown; ++c) {
    ChannelSettings ch;
    ch.channel = c;
    ch.tf = ramp(shown == 1 ? kSingleChannel : kChannelColours[c]);
    ch.importance = std::int32_t(c);
    s.channels.push_back(ch);
  }
  return s;
}

}  // namespace resoct
