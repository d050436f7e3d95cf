// Fuzz target: a whole NIfTI-1 file through open_nifti (.nii, or .nii.gz recognised by its gzip
// magic): header, decompression, voxel conversion and scaling, the level-0 passes of the
// pyramid source, then bricks and metadata.

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "resoct/io/formats/nifti.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  static fuzz::ScratchFile file("resoct-fuzz-nii");
  file.write(data, size);
  fuzz::errors_only([&] {
    const auto src = open_nifti(file.path(), BrickLayout{glm::uvec3(8), 1});
    fuzz::exercise_source(*src, 64);
  });
  return 0;
}
