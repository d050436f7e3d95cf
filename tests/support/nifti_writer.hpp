#pragma once
// NIfTI-1 / NIfTI-2 / Analyze 7.5 headers written from the specs' field layouts (nifti1.h,
// nifti2.h), in either byte order, for tests that need files the reader has not seen.

#include <cstdint>
#include <string>
#include <vector>

namespace resoct::test {

struct NiftiImageSpec {
  int version = 1;  ///< 1: 348-byte header, 2: 540-byte header
  bool big = false;
  /// "n+1" / "n+2" (single file; the default for the version), "ni1" / "ni2" (pair), "none"
  /// (Analyze 7.5: zero bytes where the magic would be).
  std::string magic;
  std::vector<std::int64_t> dim{3, 4, 3, 2};  ///< dim[0] = rank, then the sizes
  std::int16_t datatype = 2, bitpix = 8;
  double pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  std::int64_t vox_offset = -1;  ///< -1: header size + 4 for a single file, 0 for a pair
  double slope = 0, inter = 0;
  std::int32_t qform = 0, sform = 0;
  double quatern[3] = {}, qoffset[3] = {};
  double srow[3][4] = {};
};

/// The header, padded with zeros up to vox_offset for a single file (append the voxels).
std::vector<std::uint8_t> nifti_header_bytes(const NiftiImageSpec& s);

/// Appends `v` in the spec's byte order.
template <typename T>
void append_value(std::vector<std::uint8_t>& b, T v, bool big) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
  for (std::size_t i = 0; i < sizeof(T); ++i) b.push_back(big ? p[sizeof(T) - 1 - i] : p[i]);
}

}  // namespace resoct::test
