// Fuzz target: a multi-page TIFF file through open_tiff_stack (libtiff decodes; resoct checks
// page layout, size and type agreement and assembles the z stack), then bricks and metadata.

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "resoct/io/formats/tiff_stack.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  static fuzz::ScratchFile file("resoct-fuzz-tiff");
  file.write(data, size);
  fuzz::errors_only([&] {
    const auto src = open_tiff_stack(file.path(), BrickLayout{glm::uvec3(8), 1});
    fuzz::exercise_source(*src, 64);
  });
  return 0;
}
