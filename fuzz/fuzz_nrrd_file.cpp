// Fuzz target: a whole NRRD file with attached data through open_nrrd: header, line and byte
// skips, raw or gzip data, sample conversion, channel de-interleaving, the level-0 passes, then
// bricks and metadata. Headers naming a detached data file are skipped: they would make the
// fuzzer read arbitrary files of this machine (the header parser is fuzzed by nrrd_header).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "resoct/io/formats/nrrd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (text.find("data file") != std::string_view::npos ||
      text.find("datafile") != std::string_view::npos) {
    return 0;
  }
  static fuzz::ScratchFile file("resoct-fuzz-nrrd");
  file.write(data, size);
  fuzz::errors_only([&] {
    const auto src = open_nrrd(file.path(), BrickLayout{glm::uvec3(8), 1});
    fuzz::exercise_source(*src, 64);
  });
  return 0;
}
