#include <bit>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/io/formats/nifti.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

namespace {

/// Where a field sits in the NIfTI-1 (348-byte) and the NIfTI-2 (540-byte) layout.
struct Layout {
  std::size_t dim, datatype, bitpix, pixdim, vox_offset, scl_slope, scl_inter, qform_code,
      sform_code, quatern, qoffset, srow, magic;
  std::size_t dim_bytes, real_bytes, code_bytes;  ///< int16 / int64, float / double, int16 / int32
};
constexpr Layout kNifti1{40, 70, 72, 76, 108, 112, 116, 252, 254, 256, 268, 280, 344, 2, 4, 2};
constexpr Layout kNifti2{16, 12, 14, 104, 168, 176, 184, 344, 348, 352, 376, 400, 4, 8, 8, 4};

/// Reads header fields in the file's byte order.
class FieldReader {
 public:
  FieldReader(std::span<const std::byte> b, bool swap) : b_(b), swap_(swap) {}
  template <typename T>
  T get(std::size_t offset) const {
    std::byte tmp[sizeof(T)];
    std::memcpy(tmp, b_.data() + offset, sizeof(T));
    if (swap_) {
      for (std::size_t a = 0, z = sizeof(T) - 1; a < z; ++a, --z) std::swap(tmp[a], tmp[z]);
    }
    T v;
    std::memcpy(&v, tmp, sizeof(T));
    return v;
  }

 private:
  std::span<const std::byte> b_;
  bool swap_;
};

Error field_error(ErrorCode code, std::string_view location, std::uint64_t offset,
                  std::string_view field, const std::string& why) {
  return file_error(code, location, offset, "NIfTI field '" + std::string(field) + "': " + why);
}

}  // namespace

namespace {

/// One of the header's real fields (float in NIfTI-1, double in NIfTI-2) as a double.
double real(const FieldReader& r, const Layout& l, std::size_t offset) {
  return l.real_bytes == 8 ? r.get<double>(offset) : double(r.get<float>(offset));
}

std::int64_t integer(const FieldReader& r, std::size_t bytes, std::size_t offset) {
  switch (bytes) {
    case 2: return r.get<std::int16_t>(offset);
    case 4: return r.get<std::int32_t>(offset);
    default: return r.get<std::int64_t>(offset);
  }
}

/// |v| when it is a usable voxel size, else 1.
double usable_size(double v) {
  v = std::fabs(v);
  return std::isfinite(v) && v > 0.0 ? v : 1.0;
}

}  // namespace

glm::u64vec3 NiftiHeader::extent() const noexcept {
  glm::u64vec3 e(1);
  for (int i = 0; i < 3 && i < dim[0]; ++i) e[i] = std::uint64_t(dim[std::size_t(i) + 1]);
  return e;
}

std::uint64_t NiftiHeader::timepoints() const noexcept {
  return dim[0] >= 4 ? std::uint64_t(dim[4]) : 1u;
}

std::uint32_t NiftiHeader::components() const noexcept {
  return dim[0] >= 5 ? std::uint32_t(dim[5]) : 1u;
}

std::array<std::array<double, 4>, 3> NiftiHeader::voxel_to_world() const noexcept {
  std::array<std::array<double, 4>, 3> m{};
  if (sform_code > 0) return srow;
  const double dx = usable_size(pixdim[1]), dy = usable_size(pixdim[2]),
               dz = usable_size(pixdim[3]);
  if (qform_code > 0) {
    // The NIfTI-1 quaternion: (b, c, d) given, a = sqrt(1 - b^2 - c^2 - d^2), the rotation
    // scaled by the voxel sizes, k negated when qfac (pixdim[0]) is negative (nifti1.h, method 2).
    double b = quatern[0], c = quatern[1], d = quatern[2];
    double a = 1.0 - (b * b + c * c + d * d);
    if (a < 1e-7) {  // 180-degree rotation: renormalise (b, c, d), as niftilib does
      const double n = std::sqrt(b * b + c * c + d * d);
      if (n > 0.0 && std::isfinite(n)) b /= n, c /= n, d /= n;
      a = 0.0;
    } else {
      a = std::sqrt(a);
    }
    const double qfac = pixdim[0] < 0.0 ? -1.0 : 1.0;
    const double rot[3][3] = {
        {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
        {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
        {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
    const double size[3] = {dx, dy, qfac * dz};
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t col = 0; col < 3; ++col) m[r][col] = rot[r][col] * size[col];
      m[r][3] = qoffset[r];
    }
    return m;
  }
  // Method 1 (and Analyze): voxel sizes only, index origin at the world origin.
  m[0][0] = dx, m[1][1] = dy, m[2][2] = dz;
  return m;
}

glm::dvec3 NiftiHeader::spacing() const noexcept {
  const auto m = voxel_to_world();
  glm::dvec3 s(1.0);
  for (std::size_t a = 0; a < 3; ++a) {
    s[int(a)] = usable_size(std::sqrt(m[0][a] * m[0][a] + m[1][a] * m[1][a] + m[2][a] * m[2][a]));
  }
  return s;
}

bool NiftiHeader::scaled() const noexcept {
  // NIfTI-1: "If the scl_slope field is nonzero, then each voxel value in the dataset should be
  // scaled"; a zero slope means no scaling at all (scl_inter is then ignored too).
  return scl_slope != 0.0 && (scl_slope != 1.0 || scl_inter != 0.0);
}

std::size_t NiftiHeader::stored_voxel_bytes() const noexcept {
  return data_size(datatype);
}

namespace {

std::uint64_t checked_product(std::uint64_t n, std::initializer_list<std::uint64_t> factors) {
  for (std::uint64_t f : factors) {
    if (f != 0 && n > ~std::uint64_t(0) / f) {
      throw Error(ErrorCode::overflow, "NIfTI data size overflows 64 bits");
    }
    n *= f;
  }
  return n;
}

}  // namespace

std::uint64_t NiftiHeader::volume_bytes() const {
  const glm::u64vec3 e = extent();
  return checked_product(stored_voxel_bytes(), {e.x, e.y, e.z});
}

std::uint64_t NiftiHeader::data_bytes() const {
  return checked_product(volume_bytes(), {timepoints(), std::uint64_t(components())});
}

NiftiHeader parse_nifti_header(std::span<const std::byte> bytes, std::string_view location) {
  if (bytes.size() < 4) {
    throw file_error(ErrorCode::truncated, location, bytes.size(),
                     "NIfTI header needs 348 or 540 bytes, got " + std::to_string(bytes.size()));
  }
  std::uint32_t sizeof_hdr;
  std::memcpy(&sizeof_hdr, bytes.data(), 4);
  NiftiHeader h;
  bool swap = false;
  if (sizeof_hdr == 348 || sizeof_hdr == 540) {
    swap = false;
  } else if (__builtin_bswap32(sizeof_hdr) == 348u || __builtin_bswap32(sizeof_hdr) == 540u) {
    swap = true;
    sizeof_hdr = __builtin_bswap32(sizeof_hdr);
  } else {
    throw file_error(ErrorCode::bad_magic, location, 0,
                     "sizeof_hdr is neither 348 (NIfTI-1, Analyze 7.5) nor 540 (NIfTI-2) in "
                     "either byte order (not a NIfTI file)");
  }
  h.version = sizeof_hdr == 540 ? 2 : 1;
  if (bytes.size() < h.header_bytes()) {
    throw file_error(ErrorCode::truncated, location, bytes.size(),
                     "NIfTI-" + std::to_string(h.version) + " header needs " +
                         std::to_string(h.header_bytes()) + " bytes, got " +
                         std::to_string(bytes.size()));
  }
  const Layout& l = h.version == 2 ? kNifti2 : kNifti1;
  const bool host_little = std::endian::native == std::endian::little;
  h.endian = (host_little != swap) ? Endian::little : Endian::big;
  const FieldReader r(bytes, swap);
  const char* magic = reinterpret_cast<const char*>(bytes.data() + l.magic);
  if (h.version == 2) {
    // NIfTI-2's magic carries the PNG-style "\r\n\032\n" tail that catches text-mode transfers.
    if (std::memcmp(magic, "n+2\0\r\n\032\n", 8) == 0) {
      h.form = NiftiForm::single;
    } else if (std::memcmp(magic, "ni2\0\r\n\032\n", 8) == 0) {
      h.form = NiftiForm::pair;
    } else {
      throw file_error(ErrorCode::bad_magic, location, l.magic,
                       "sizeof_hdr is 540 but the magic is not \"n+2\" or \"ni2\" followed by "
                       "\\0\\r\\n\\032\\n (not a NIfTI-2 file, or damaged in a text-mode copy)");
    }
  } else if (std::memcmp(magic, "n+1\0", 4) == 0) {
    h.form = NiftiForm::single;
  } else if (std::memcmp(magic, "ni1\0", 4) == 0) {
    h.form = NiftiForm::pair;
  } else {
    h.form = NiftiForm::analyze;
  }
  for (std::size_t i = 0; i < 8; ++i) h.dim[i] = integer(r, l.dim_bytes, l.dim + l.dim_bytes * i);
  const auto dim_offset = [&](std::int64_t i) {
    return std::uint64_t(l.dim + l.dim_bytes * std::size_t(i));
  };
  if (h.dim[0] < 1 || h.dim[0] > 7) {
    throw field_error(ErrorCode::corrupt, location, l.dim, "dim[0]",
                      "rank " + std::to_string(h.dim[0]) + " outside 1..7");
  }
  for (std::int64_t i = 1; i <= h.dim[0]; ++i) {
    if (h.dim[std::size_t(i)] < 1) {
      throw field_error(ErrorCode::corrupt, location, dim_offset(i),
                        "dim[" + std::to_string(i) + "]",
                        "must be >= 1, got " + std::to_string(h.dim[std::size_t(i)]));
    }
  }
  for (std::int64_t i = 6; i <= h.dim[0]; ++i) {
    if (h.dim[std::size_t(i)] != 1) {
      throw field_error(ErrorCode::unsupported, location, dim_offset(i),
                        "dim[" + std::to_string(i) + "]", "dimensions 6 and 7 must be 1");
    }
  }
  if (h.dim[0] >= 5 && h.dim[5] > std::int64_t(kMaxChannels)) {
    throw field_error(ErrorCode::unsupported, location, dim_offset(5), "dim[5]",
                      std::to_string(h.dim[5]) + " components exceed " +
                          std::to_string(kMaxChannels) + " channels");
  }
  const std::int16_t datatype = r.get<std::int16_t>(l.datatype);
  const std::int16_t bitpix = r.get<std::int16_t>(l.bitpix);
  switch (datatype) {
    case 2: h.datatype = DataType::u8; break;
    case 256: h.datatype = DataType::i8; break;
    case 4: h.datatype = DataType::i16; break;
    case 512: h.datatype = DataType::u16; break;
    case 8: h.datatype = DataType::i32; break;
    case 768: h.datatype = DataType::u32; break;
    case 16: h.datatype = DataType::f32; break;
    case 64: h.datatype = DataType::f64; break;
    default:
      throw field_error(ErrorCode::unsupported, location, l.datatype, "datatype",
                        std::to_string(datatype) +
                            " is not supported (2 = uint8, 256 = int8, 4 = int16, 512 = uint16, "
                            "8 = int32, 768 = uint32, 16 = float32, 64 = float64)");
  }
  if (bitpix != std::int16_t(8 * data_size(h.datatype))) {
    throw field_error(
        ErrorCode::corrupt, location, l.bitpix, "bitpix",
        std::to_string(bitpix) + " disagrees with datatype " + std::to_string(datatype));
  }
  for (std::size_t i = 0; i < 8; ++i) h.pixdim[i] = real(r, l, l.pixdim + l.real_bytes * i);
  // A single file's data follows its header; a pair's .img may start with its data (0).
  const double min_offset = h.form == NiftiForm::single ? double(h.header_bytes()) : 0.0;
  if (h.version == 2) {
    const std::int64_t v = r.get<std::int64_t>(l.vox_offset);
    if (double(v) < min_offset) {
      throw field_error(
          ErrorCode::corrupt, location, l.vox_offset, "vox_offset",
          "must be >= " + std::to_string(std::int64_t(min_offset)) + ", got " + std::to_string(v));
    }
    h.vox_offset = std::uint64_t(v);
  } else {
    const float v = r.get<float>(l.vox_offset);
    if (!(v >= min_offset) || !(v < 1e15f) || v != std::floor(v)) {
      throw field_error(ErrorCode::corrupt, location, l.vox_offset, "vox_offset",
                        "must be a whole number >= " + std::to_string(std::int64_t(min_offset)) +
                            ", got " + std::to_string(v));
    }
    h.vox_offset = std::uint64_t(v);
  }
  if (h.form != NiftiForm::analyze) {
    // Non-finite values read as 0, as niftilib's FIXED_FLOAT does: a NaN or infinite slope
    // therefore means "no scaling" instead of turning every voxel into NaN or inf (an invisible
    // volume), and a non-finite intercept is no offset. Analyze 7.5 has no such fields (SPM's
    // "funused1" scale factor at the slope's offset is not applied).
    h.scl_slope = real(r, l, l.scl_slope);
    h.scl_inter = real(r, l, l.scl_inter);
    if (!std::isfinite(h.scl_slope)) h.scl_slope = 0.0;
    if (!std::isfinite(h.scl_inter)) h.scl_inter = 0.0;
    h.qform_code = std::int32_t(integer(r, l.code_bytes, l.qform_code));
    h.sform_code = std::int32_t(integer(r, l.code_bytes, l.sform_code));
    for (std::size_t i = 0; i < 3; ++i) {
      h.quatern[i] = real(r, l, l.quatern + l.real_bytes * i);
      h.qoffset[i] = real(r, l, l.qoffset + l.real_bytes * i);
    }
    for (std::size_t row = 0; row < 3; ++row) {
      for (std::size_t c = 0; c < 4; ++c) {
        h.srow[row][c] = real(r, l, l.srow + l.real_bytes * (4 * row + c));
      }
    }
  }
  try {
    (void)h.data_bytes();
  } catch (const Error&) {
    throw field_error(ErrorCode::overflow, location, l.dim, "dim", "data size overflows 64 bits");
  }
  return h;
}

}  // namespace resoct
