// Fuzz target: the NIfTI-1 / NIfTI-2 / Analyze 7.5 header (the first 348 or 540 bytes of a .nii
// or .hdr). A parsed header must satisfy the invariants nifti.hpp states (rank 1..7, dimensions
// >= 1, at most 256 components, a single file's vox_offset past its header, a data size that
// fits 64 bits), and its derived quantities (spacing, the placement's axis order) must be
// usable.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_support.hpp"
#include "resoct/io/formats/nifti.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  fuzz::errors_only([&] {
    const NiftiHeader h = parse_nifti_header(bytes, "fuzz.nii");
    if (h.dim[0] < 1 || h.dim[0] > 7) fuzz::fail("rank outside 1..7 accepted");
    const glm::u64vec3 e = h.extent();
    if (e.x == 0 || e.y == 0 || e.z == 0) fuzz::fail("zero extent accepted");
    if (h.components() < 1 || h.components() > 256) {
      fuzz::fail("component count outside 1..256 accepted");
    }
    if (h.timepoints() < 1) fuzz::fail("zero timepoints accepted");
    if (h.form == NiftiForm::single && h.vox_offset < h.header_bytes()) {
      fuzz::fail("vox_offset inside the header accepted");
    }
    (void)h.data_bytes();
    const glm::dvec3 s = h.spacing();
    for (int a = 0; a < 3; ++a) {
      if (!(std::isfinite(s[a]) && s[a] > 0.0)) fuzz::fail("spacing not positive and finite");
    }
    (void)h.scaled();
  });
  return 0;
}
