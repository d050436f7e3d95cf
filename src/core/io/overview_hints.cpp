#include "resoct/io/overview_hints.hpp"

#include <algorithm>

#include "resoct/base/error.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/sources/value_histogram.hpp"

namespace resoct {

namespace {
// Bins of the coarse histogram: the percentile is linear within a bin, so 1024 bins place it
// within 0.1 % of the value range.
constexpr std::uint32_t kOverviewHistogramBins = 1024;
}  // namespace

std::optional<glm::dvec3> parse_hex_colour(std::string_view text) noexcept {
  if (!text.empty() && text.front() == '#') text.remove_prefix(1);
  if (text.size() != 6) return std::nullopt;
  const auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  glm::dvec3 rgb{0.0};
  for (int i = 0; i < 3; ++i) {
    const int hi = nibble(text[std::size_t(2 * i)]), lo = nibble(text[std::size_t(2 * i + 1)]);
    if (hi < 0 || lo < 0) return std::nullopt;
    rgb[i] = double(hi * 16 + lo) / 255.0;
  }
  return rgb;
}

OverviewHints overview_hints(const BrickSource& source) {
  OverviewHints hints;
  if (const auto* zarr = dynamic_cast<const OmeZarrSource*>(&source)) {
    const auto& omero = zarr->multiscales().channels;
    const std::uint32_t channels = source.volume().channels;
    for (std::size_t c = 0; c < omero.size() && c < channels; ++c) {
      ChannelDisplayHint h;
      h.colour = parse_hex_colour(omero[c].color);
      h.window = omero[c].window;
      hints.channels.push_back(h);
    }
  }
  // Without a window, the channels the overview shows get a histogram of their coarsest level
  // (one brick each), whose percentiles overview_scene turns into the ramp.
  const std::uint32_t shown = std::min(source.volume().channels, kOverviewChannels);
  if (hints.channels.size() < shown) hints.channels.resize(shown);
  for (std::uint32_t c = 0; c < shown; ++c) {
    if (!hints.channels[c].window) {
      try {
        hints.channels[c].histogram = coarse_value_histogram(source, c, kOverviewHistogramBins);
      } catch (const Error&) {
        // An unreadable brick leaves the default ramp; rendering reports the failure itself.
      }
    }
  }
  return hints;
}

}  // namespace resoct
