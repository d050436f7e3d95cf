// Fuzz target: OME-NGFF 0.4 `.zattrs` (multiscales, axes, omero). A parsed image must satisfy
// what ome_multiscales.hpp promises the zarr source: one scale and translation per axis, scales
// positive and finite, at least one dataset, a known axis set with a spatial axis.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "resoct/io/formats/ome_multiscales.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  fuzz::errors_only([&] {
    const OmeMultiscales m = parse_ome_multiscales(json, "fuzz/.zattrs");
    if (m.datasets.empty()) fuzz::fail("no datasets accepted");
    if (m.units.size() != m.axes.size()) fuzz::fail("units and axes differ in length");
    if (m.axis_index('x') < 0 && m.axis_index('y') < 0 && m.axis_index('z') < 0) {
      fuzz::fail("no spatial axis accepted");
    }
    for (const OmeDataset& d : m.datasets) {
      if (d.scale.size() != m.axes.size() || d.translation.size() != m.axes.size()) {
        fuzz::fail("dataset '" + d.path + "': scale/translation length differs from the axes");
      }
      for (double s : d.scale) {
        if (!(std::isfinite(s) && s > 0.0)) fuzz::fail("non-positive or non-finite scale");
      }
    }
    for (const OmeChannel& c : m.channels) {
      if (c.window && !(c.window->lo < c.window->hi)) fuzz::fail("empty channel window accepted");
    }
  });
  return 0;
}
