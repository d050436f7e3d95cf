#include "resoct/scene/overview_scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "resoct/base/error.hpp"

namespace resoct {

namespace {

// Colours that stay apart when channels overlap additively: the usual fluorescence pseudo-colours
// (a single channel gets a warm white, which reads as density rather than as a label).
constexpr glm::dvec3 kSingleChannel{1.0, 0.85, 0.6};
constexpr glm::dvec3 kChannelColours[kOverviewChannels] = {
    {0.2, 1.0, 0.2}, {1.0, 0.2, 1.0}, {0.2, 0.8, 1.0}, {1.0, 0.8, 0.1}};

// Transparent up to `lo`, opacity rising linearly to 0.5 at `hi` (0 <= lo < hi <= 1), flat after.
TransferFunction ramp(const glm::dvec3& c, double lo = 0.1, double hi = 1.0) {
  std::vector<TfPoint> p{TfPoint{0.0, glm::dvec4(c, 0.0)}};
  if (lo > 0.0) p.push_back(TfPoint{lo, glm::dvec4(c, 0.0)});
  p.push_back(TfPoint{hi, glm::dvec4(c, 0.5)});
  if (hi < 1.0) p.push_back(TfPoint{1.0, glm::dvec4(c, 0.5)});
  return TransferFunction(std::move(p));
}

// A channel's ramp ends [lo, hi] in normalized units from its hint, or nothing.
std::optional<std::pair<double, double>> hinted_ramp(const VolumeDesc& volume, std::uint32_t c,
                                                     const ChannelDisplayHint& h) {
  if (h.window) {
    const ValueRange r = volume.range(c);
    const double offset = volume.value_offset();
    const auto norm = [&](double v) {
      return std::clamp((v + offset - r.lo) / (r.hi - r.lo), 0.0, 1.0);
    };
    const double lo = norm(h.window->lo), hi = norm(h.window->hi);
    if (std::isfinite(lo) && std::isfinite(hi) && lo < hi) return std::pair{lo, hi};
  }
  if (!h.histogram.empty()) {
    const auto lo = histogram_percentile(h.histogram, kOverviewLowPercentile);
    const auto hi = histogram_percentile(h.histogram, kOverviewHighPercentile);
    if (lo && hi) {
      // A narrow distribution (one bin) still gets a ramp one bin wide.
      const double bin = 1.0 / double(h.histogram.size());
      double a = *lo, b = *hi;
      if (b - a < bin) b = std::min(1.0, a + bin);
      if (b - a < bin) a = std::max(0.0, b - bin);
      if (a < b) return std::pair{a, b};
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<double> histogram_percentile(const std::vector<std::uint64_t>& histogram, double p) {
  double total = 0.0;
  for (std::uint64_t n : histogram) total += double(n);
  if (total <= 0.0) return std::nullopt;
  const double want = std::clamp(p, 0.0, 100.0) / 100.0 * total;
  const double n = double(histogram.size());
  double below = 0.0;
  for (std::size_t i = 0; i < histogram.size(); ++i) {
    const double count = double(histogram[i]);
    if (count > 0.0 && below + count >= want) {
      return (double(i) + std::clamp((want - below) / count, 0.0, 1.0)) / n;
    }
    below += count;
  }
  return 1.0;
}

Scene overview_scene(const VolumeDesc& volume, const Viewport& viewport,
                     const OverviewHints& hints) {
  Scene s = overview_scene(volume, viewport);
  for (ChannelSettings& ch : s.channels) {
    if (ch.channel >= hints.channels.size()) continue;
    const ChannelDisplayHint& h = hints.channels[ch.channel];
    glm::dvec3 colour = ch.tf.points().back().rgba;
    if (h.colour) {
      for (int i = 0; i < 3; ++i) {
        const double v = (*h.colour)[i];
        if (!std::isfinite(v) || v < 0.0 || v > 1.0) {
          throw invalid_parameter("hints", "channel " + std::to_string(ch.channel) +
                                               ": colour components must be in [0, 1]");
        }
      }
      colour = *h.colour;
    }
    const auto ends = hinted_ramp(volume, ch.channel, h);
    ch.tf = ends ? ramp(colour, ends->first, ends->second) : ramp(colour);
  }
  return s;
}

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
