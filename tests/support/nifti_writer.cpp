#include "support/nifti_writer.hpp"

#include <algorithm>
#include <cstring>

namespace resoct::test {

std::vector<std::uint8_t> nifti_header_bytes(const NiftiImageSpec& s) {
  const bool v2 = s.version == 2;
  const std::string magic = s.magic.empty() ? (v2 ? "n+2" : "n+1") : s.magic;
  const bool single = magic[1] == '+';
  const std::size_t header = v2 ? 540 : 348;
  const std::int64_t offset = s.vox_offset >= 0 ? s.vox_offset : single ? header + 4 : 0;
  std::vector<std::uint8_t> h(single ? std::max(std::size_t(offset), header) : header, 0);
  auto put = [&](std::size_t at, const void* v, std::size_t n) {
    const auto* p = static_cast<const std::uint8_t*>(v);
    for (std::size_t i = 0; i < n; ++i) h[at + i] = s.big ? p[n - 1 - i] : p[i];
  };
  // A field that is float / int16 in NIfTI-1 and double / int64 (or int32) in NIfTI-2.
  auto real = [&](std::size_t at, double v) {
    if (v2) return put(at, &v, 8);
    const float f = float(v);
    put(at, &f, 4);
  };
  const std::int32_t sizeof_hdr = std::int32_t(header);
  put(0, &sizeof_hdr, 4);
  const std::size_t real_bytes = v2 ? 8 : 4;
  const std::size_t dim_at = v2 ? 16 : 40, pixdim_at = v2 ? 104 : 76;
  for (std::size_t i = 0; i < 8; ++i) {
    const std::int64_t d = i < s.dim.size() ? s.dim[i] : 1;
    if (v2) {
      put(dim_at + 8 * i, &d, 8);
    } else {
      const auto d16 = std::int16_t(d);
      put(dim_at + 2 * i, &d16, 2);
    }
    real(pixdim_at + real_bytes * i, s.pixdim[i]);
  }
  put(v2 ? 12 : 70, &s.datatype, 2);
  put(v2 ? 14 : 72, &s.bitpix, 2);
  if (v2) {
    put(168, &offset, 8);
  } else {
    real(108, double(offset));
  }
  real(v2 ? 176 : 112, s.slope);
  real(v2 ? 184 : 116, s.inter);
  if (v2) {
    put(344, &s.qform, 4);
    put(348, &s.sform, 4);
  } else {
    const auto q = std::int16_t(s.qform), f = std::int16_t(s.sform);
    put(252, &q, 2);
    put(254, &f, 2);
  }
  const std::size_t quatern_at = v2 ? 352 : 256, qoffset_at = v2 ? 376 : 268,
                    srow_at = v2 ? 400 : 280;
  for (std::size_t i = 0; i < 3; ++i) {
    real(quatern_at + real_bytes * i, s.quatern[i]);
    real(qoffset_at + real_bytes * i, s.qoffset[i]);
    for (std::size_t c = 0; c < 4; ++c) real(srow_at + real_bytes * (4 * i + c), s.srow[i][c]);
  }
  if (magic != "none") {
    if (v2) {
      std::memcpy(h.data() + 4, magic.data(), 3);
      std::memcpy(h.data() + 8, "\r\n\032\n", 4);
    } else {
      std::memcpy(h.data() + 344, magic.data(), 3);
    }
  }
  return h;
}

}  // namespace resoct::test
