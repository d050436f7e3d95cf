// Fuzz target: the NRRD header. A parsed header must satisfy what nrrd.hpp promises the reader:
// 1..4 sizes, each >= 1; a channel axis that exists; a positive finite spacing; the header end
// inside the text; channels >= 1 and a data size that fits 64 bits or throws Error(overflow).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "resoct/io/formats/nrrd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  fuzz::errors_only([&] {
    const NrrdHeader h = parse_nrrd_header(text, "fuzz.nrrd");
    if (h.sizes.empty() || h.sizes.size() > 4) fuzz::fail("axis count outside 1..4 accepted");
    for (std::uint64_t s : h.sizes) {
      if (s == 0) fuzz::fail("zero size accepted");
    }
    if (h.channel_axis < -1 || h.channel_axis >= int(h.sizes.size())) {
      fuzz::fail("channel axis outside the axes");
    }
    if (h.header_bytes > text.size()) fuzz::fail("header end beyond the text");
    for (int a = 0; a < 3; ++a) {
      if (!(std::isfinite(h.spacing[a]) && h.spacing[a] > 0.0)) {
        fuzz::fail("spacing not positive and finite");
      }
    }
    const glm::u64vec3 e = h.extent();
    if (e.x == 0 || e.y == 0 || e.z == 0 || h.channels() == 0) fuzz::fail("empty volume accepted");
    (void)h.data_bytes();
  });
  return 0;
}
