#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "resoct/error.hpp"
#include "resoct/formats/nifti.hpp"

namespace resoct {

namespace {

constexpr std::size_t kHeaderSize = 348;

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

glm::u64vec3 NiftiHeader::extent() const noexcept {
  glm::u64vec3 e(1);
  for (int i = 0; i < 3 && i < dim[0]; ++i) e[i] = std::uint64_t(dim[std::size_t(i) + 1]);
  return e;
}

std::uint32_t NiftiHeader::volumes() const noexcept {
  return dim[0] >= 4 ? std::uint32_t(dim[4]) : 1u;
}

glm::dvec3 NiftiHeader::spacing() const noexcept {
  glm::dvec3 s(1.0);
  for (int a = 0; a < 3; ++a) {
    double v = std::fabs(double(pixdim[std::size_t(a) + 1]));
    if (sform_code > 0) {
      const double x = srow[0][std::size_t(a)], y = srow[1][std::size_t(a)],
                   z = srow[2][std::size_t(a)];
      const double len = std::sqrt(x * x + y * y + z * z);
      if (std::isfinite(len) && len > 0.0) v = len;
    }
    s[a] = std::isfinite(v) && v > 0.0 ? v : 1.0;
  }
  return s;
}

bool NiftiHeader::scaled() const noexcept {
  // NIfTI-1: "If the scl_slope field is nonzero, then each voxel value in the dataset should be
  // scaled"; a zero slope means no scaling at all (scl_inter is then ignored too).
  return scl_slope != 0.0f && (scl_slope != 1.0f || scl_inter != 0.0f);
}

std::size_t NiftiHeader::stored_voxel_bytes() const noexcept {
  return data_size(datatype);
}

std::uint64_t NiftiHeader::data_bytes() const {
  const glm::u64vec3 e = extent();
  std::uint64_t n = stored_voxel_bytes();
  for (std::uint64_t f : {e.x, e.y, e.z, std::uint64_t(volumes())}) {
    if (f != 0 && n > ~std::uint64_t(0) / f) {
      throw Error(ErrorCode::overflow, "NIfTI data size overflows 64 bits");
    }
    n *= f;
  }
  return n;
}

NiftiHeader parse_nifti_header(std::span<const std::byte> bytes, std::string_view location) {
  if (bytes.size() < kHeaderSize) {
    throw file_error(ErrorCode::truncated, location, bytes.size(),
                     "NIfTI header needs 348 bytes, got " + std::to_string(bytes.size()));
  }
  std::int32_t sizeof_hdr;
  std::memcpy(&sizeof_hdr, bytes.data(), 4);
  NiftiHeader h;
  bool swap = false;
  if (sizeof_hdr == 348) {
    swap = false;
  } else if (__builtin_bswap32(std::uint32_t(sizeof_hdr)) == 348u) {
    swap = true;
  } else {
    throw file_error(ErrorCode::bad_magic, location, 0,
                     "sizeof_hdr is not 348 in either byte order (not a NIfTI-1 file)");
  }
  const bool host_little = std::endian::native == std::endian::little;
  h.endian = (host_little != swap) ? Endian::little : Endian::big;
  const FieldReader r(bytes, swap);
  const char* magic = reinterpret_cast<const char*>(bytes.data() + 344);
  if (std::memcmp(magic, "ni1\0", 4) == 0) {
    throw file_error(ErrorCode::unsupported, location, 344,
                     "two-file NIfTI (.hdr/.img, magic \"ni1\") is not supported");
  }
  if (std::memcmp(magic, "n+1\0", 4) != 0) {
    throw file_error(ErrorCode::bad_magic, location, 344, "magic is not \"n+1\"");
  }
  for (std::size_t i = 0; i < 8; ++i) h.dim[i] = r.get<std::int16_t>(40 + 2 * i);
  if (h.dim[0] < 1 || h.dim[0] > 7) {
    throw field_error(ErrorCode::corrupt, location, 40, "dim[0]",
                      "rank " + std::to_string(h.dim[0]) + " outside 1..7");
  }
  for (std::int64_t i = 1; i <= h.dim[0]; ++i) {
    if (h.dim[std::size_t(i)] < 1) {
      throw field_error(ErrorCode::corrupt, location, std::uint64_t(40 + 2 * i),
                        "dim[" + std::to_string(i) + "]",
                        "must be >= 1, got " + std::to_string(h.dim[std::size_t(i)]));
    }
  }
  for (std::int64_t i = 5; i <= h.dim[0]; ++i) {
    if (h.dim[std::size_t(i)] != 1) {
      throw field_error(ErrorCode::unsupported, location, std::uint64_t(40 + 2 * i),
                        "dim[" + std::to_string(i) + "]", "dimensions 5..7 must be 1");
    }
  }
  if (h.volumes() > 256) {
    throw field_error(ErrorCode::unsupported, location, 48, "dim[4]",
                      std::to_string(h.volumes()) + " volumes exceed 256 channels");
  }
  const std::int16_t datatype = r.get<std::int16_t>(70);
  const std::int16_t bitpix = r.get<std::int16_t>(72);
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
      throw field_error(ErrorCode::unsupported, location, 70, "datatype",
                        std::to_string(datatype) +
                            " is not supported (2 = uint8, 256 = int8, 4 = int16, 512 = uint16, "
                            "8 = int32, 768 = uint32, 16 = float32, 64 = float64)");
  }
  if (bitpix != std::int16_t(8 * data_size(h.datatype))) {
    throw field_error(
        ErrorCode::corrupt, location, 72, "bitpix",
        std::to_string(bitpix) + " disagrees with datatype " + std::to_string(datatype));
  }
  for (std::size_t i = 0; i < 8; ++i) h.pixdim[i] = r.get<float>(76 + 4 * i);
  const float vox_offset = r.get<float>(108);
  if (!(vox_offset >= 348.0f) || !(vox_offset < 1e15f) || vox_offset != std::floor(vox_offset)) {
    throw field_error(ErrorCode::corrupt, location, 108, "vox_offset",
                      "must be a whole number >= 348, got " + std::to_string(vox_offset));
  }
  h.vox_offset = std::uint64_t(vox_offset);
  // Non-finite values read as 0, as niftilib's FIXED_FLOAT does: a NaN or infinite slope
  // therefore means "no scaling" instead of turning every voxel into NaN or inf (an invisible
  // volume), and a non-finite intercept is no offset.
  h.scl_slope = r.get<float>(112);
  h.scl_inter = r.get<float>(116);
  if (!std::isfinite(h.scl_slope)) h.scl_slope = 0.0f;
  if (!std::isfinite(h.scl_inter)) h.scl_inter = 0.0f;
  h.qform_code = r.get<std::int16_t>(252);
  h.sform_code = r.get<std::int16_t>(254);
  for (std::size_t row = 0; row < 3; ++row) {
    for (std::size_t c = 0; c < 4; ++c) h.srow[row][c] = r.get<float>(280 + 16 * row + 4 * c);
  }
  try {
    (void)h.data_bytes();
  } catch (const Error&) {
    throw field_error(ErrorCode::overflow, location, 40, "dim", "data size overflows 64 bits");
  }
  return h;
}

}  // namespace resoct
