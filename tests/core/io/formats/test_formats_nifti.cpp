// NIfTI-1: headers written by the test from the NIfTI-1 layout (every datatype, both byte orders,
// scaling, .nii.gz; NIfTI-2, pairs, time and placement are in test_formats_nifti_forms.cpp),
// damaged headers and files, and the real MRI volumes of Debian's mricron-data (Colin27 T1, atlases
// on its grid, an int16 atlas with header extensions, a float32 template).

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/nifti.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/io/open_source.hpp"
#include "support/brick_compare.hpp"
#include "support/expect_error.hpp"
#include "support/gzip_bytes.hpp"
#include "support/level0_values.hpp"

using namespace resoct;
using test::TempDir;

namespace {

const std::string kTemplates = "/usr/share/mricron/templates/";

struct Spec {
  std::int16_t datatype = 2, bitpix = 8;
  std::vector<std::int16_t> dim{3, 5, 4, 3};
  float pixdim[4] = {1, 1, 1, 1};
  float slope = 0, inter = 0;
  std::int16_t qform = 0, sform = 0;
  float srow[3][4] = {};
  float vox_offset = 352;
  bool big = false;
  const char* magic = "n+1";
};

/// Writes a header by the NIfTI-1 layout (field offsets from nifti1.h) in either byte order.
std::vector<std::uint8_t> header(const Spec& s) {
  std::vector<std::uint8_t> h(std::size_t(s.vox_offset), 0);
  auto put = [&](std::size_t at, const void* v, std::size_t n) {
    const auto* p = static_cast<const std::uint8_t*>(v);
    for (std::size_t i = 0; i < n; ++i) h[at + i] = s.big ? p[n - 1 - i] : p[i];
  };
  const std::int32_t sizeof_hdr = 348;
  put(0, &sizeof_hdr, 4);
  for (std::size_t i = 0; i < 8; ++i) {
    const std::int16_t d = i < s.dim.size() ? s.dim[i] : std::int16_t(1);
    put(40 + 2 * i, &d, 2);
  }
  put(70, &s.datatype, 2);
  put(72, &s.bitpix, 2);
  for (std::size_t i = 0; i < 4; ++i) put(76 + 4 * i, &s.pixdim[i], 4);
  put(108, &s.vox_offset, 4);
  put(112, &s.slope, 4);
  put(116, &s.inter, 4);
  put(252, &s.qform, 2);
  put(254, &s.sform, 2);
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 4; ++c) put(280 + 16 * r + 4 * c, &s.srow[r][c], 4);
  std::memcpy(h.data() + 344, s.magic, 4);
  return h;
}

template <typename T>
void append(std::vector<std::uint8_t>& b, T v, bool big) {
  std::uint8_t tmp[sizeof(T)];
  std::memcpy(tmp, &v, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) b.push_back(big ? tmp[sizeof(T) - 1 - i] : tmp[i]);
}

// Every datatype resoct reads, kept as data_mapping() says: values come back in the file's
// units (stored value minus the mapping's offset), and the data range is the data's own signed
// range, not the stored one. The values are exact in every mapping (|v| < 2^24 for the 32-bit
// integers, multiples of 1/4 for the floats).
TEST(Nifti, EveryDatatypeBothByteOrdersPlainAndGzip) {
  TempDir dir;
  struct T {
    std::int16_t datatype, bitpix;
    VoxelType stored;
    std::optional<DataType> data_type;  // set when the file's type is not the stored one
  };
  for (const T t :
       {T{2, 8, VoxelType::u8, {}}, T{256, 8, VoxelType::u8, DataType::i8},
        T{4, 16, VoxelType::u16, DataType::i16}, T{512, 16, VoxelType::u16, {}},
        T{8, 32, VoxelType::f32, DataType::i32}, T{768, 32, VoxelType::f32, DataType::u32},
        T{16, 32, VoxelType::f32, {}}, T{64, 64, VoxelType::f32, DataType::f64}}) {
    for (bool big : {false, true}) {
      for (bool gz : {false, true}) {
        SCOPED_TRACE(std::to_string(t.datatype) + (big ? " big" : " little") + (gz ? " gz" : ""));
        Spec s;
        s.datatype = t.datatype;
        s.bitpix = t.bitpix;
        s.big = big;
        s.pixdim[1] = 0.7f, s.pixdim[2] = 0.8f, s.pixdim[3] = 2.5f;
        auto b = header(s);
        std::vector<double> want;
        for (int i = 0; i < 60; ++i) {
          double v = double((i * 37) % 250);
          switch (t.datatype) {
            case 256: v = double(i * 37 % 256) - 128.0; break;
            case 4: v = double(i * 997 % 6000) - 3000.0; break;
            case 512: v *= 200.0; break;
            case 8: v = double(i * 99991 % 16000000) - 8000000.0; break;
            case 768: v = double(i * 99991 % 16000000) + 7.0; break;
            case 16:
            case 64: v = double(i) * 0.25 - 4.0; break;
          }
          want.push_back(v);
          switch (t.datatype) {
            case 2: append(b, std::uint8_t(v), big); break;
            case 256: append(b, std::int8_t(v), big); break;
            case 4: append(b, std::int16_t(v), big); break;
            case 512: append(b, std::uint16_t(v), big); break;
            case 8: append(b, std::int32_t(v), big); break;
            case 768: append(b, std::uint32_t(v), big); break;
            case 16: append(b, float(v), big); break;
            case 64: append(b, v, big); break;
          }
        }
        const std::string path = dir.file(gz ? "v.nii.gz" : "v.nii");
        test::write_bytes(path, gz ? test::gzip_bytes(b) : b);
        const auto src = open_source(path, BrickLayout{glm::uvec3(4), 1});
        const VolumeDesc& d = src->volume();
        EXPECT_EQ(d.type, t.stored);
        EXPECT_EQ(d.data_type, t.data_type);
        EXPECT_EQ(d.extent, glm::u64vec3(5, 4, 3));
        EXPECT_NEAR(d.spacing.x, 0.7, 1e-6);
        EXPECT_NEAR(d.spacing.z, 2.5, 1e-6);
        std::vector<double> got = level0_values(*src, 0);
        for (double& v : got) v -= d.value_offset();
        EXPECT_EQ(got, want);
        double lo = 1e300, hi = -1e300;
        for (double v : want) lo = std::min(lo, v), hi = std::max(hi, v);
        EXPECT_EQ(d.data_range(0), (ValueRange{lo, hi}));
      }
    }
  }
}

// niftilib's rule: a NaN or infinite scl_slope / scl_inter reads as 0, and a zero slope means
// no scaling at all (scl_inter ignored). A NaN slope used to scale every voxel to NaN: a volume
// with no finite value, invisible, without a word.
TEST(Nifti, NonFiniteOrZeroSlopeMeansNoScaling) {
  TempDir dir;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct Case {
    std::int16_t datatype, bitpix;
    float slope, inter;
    VoxelType type;
    double scale, offset;  // expected value = scale * stored + offset
  };
  for (const Case c :
       {Case{2, 8, nan, 0, VoxelType::u8, 1, 0}, Case{2, 8, inf, 0, VoxelType::u8, 1, 0},
        Case{2, 8, -inf, 5, VoxelType::u8, 1, 0}, Case{2, 8, nan, nan, VoxelType::u8, 1, 0},
        Case{2, 8, 0, 7, VoxelType::u8, 1, 0}, Case{512, 16, nan, -3, VoxelType::u16, 1, 0},
        Case{4, 16, nan, 2, VoxelType::u16, 1, 32768}, Case{16, 32, inf, 1, VoxelType::f32, 1, 0},
        Case{2, 8, 2, nan, VoxelType::f32, 2, 0}, Case{2, 8, 2, -inf, VoxelType::f32, 2, 0},
        Case{2, 8, 1, 0.5f, VoxelType::f32, 1, 0.5}}) {
    SCOPED_TRACE("datatype " + std::to_string(c.datatype) + " slope " + std::to_string(c.slope) +
                 " inter " + std::to_string(c.inter));
    Spec s;
    s.datatype = c.datatype;
    s.bitpix = c.bitpix;
    s.slope = c.slope;
    s.inter = c.inter;
    auto b = header(s);
    std::vector<double> want;
    for (int i = 0; i < 60; ++i) {
      const double v = double(i * 3 + 1);
      want.push_back(c.scale * v + c.offset);
      if (c.datatype == 2) append(b, std::uint8_t(v), false);
      if (c.datatype == 4) append(b, std::int16_t(-v), false), want.back() = c.offset - v;
      if (c.datatype == 512) append(b, std::uint16_t(v), false);
      if (c.datatype == 16) append(b, float(v), false);
    }
    const auto hb = std::as_bytes(std::span(b));
    const NiftiHeader h = parse_nifti_header(hb, "s.nii");
    EXPECT_TRUE(std::isfinite(h.scl_slope));
    EXPECT_TRUE(std::isfinite(h.scl_inter));
    EXPECT_EQ(h.scaled(), c.type == VoxelType::f32 && c.datatype == 2);
    test::write_bytes(dir.file("s.nii"), b);
    const auto src = open_nifti(dir.file("s.nii"), BrickLayout{glm::uvec3(4), 1});
    EXPECT_EQ(src->volume().type, c.type);
    EXPECT_EQ(level0_values(*src, 0), want);
    const ValueRange r = src->volume().range(0);
    EXPECT_TRUE(std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo < r.hi);
  }
}

TEST(Nifti, DamagedHeadersAndFiles) {
  TempDir dir;
  auto bytes = [](const std::vector<std::uint8_t>& v) {
    return std::vector<std::byte>(reinterpret_cast<const std::byte*>(v.data()),
                                  reinterpret_cast<const std::byte*>(v.data()) + v.size());
  };
  Spec good;
  const auto h = header(good);
  const auto hb = bytes(h);
  EXPECT_RESOCT_ERROR(parse_nifti_header(std::span(hb).first(200), "x.nii"), ErrorCode::truncated,
                      "x.nii");
  auto bad = h;
  bad[0] = 99;
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(bad), "x.nii"), ErrorCode::bad_magic, "sizeof_hdr");
  Spec pair;  // a pair header parses; open_nifti refuses it in a .nii (test_formats_nifti_forms)
  pair.magic = "ni1";
  EXPECT_EQ(parse_nifti_header(bytes(header(pair)), "x.nii").form, NiftiForm::pair);
  Spec rank;
  rank.dim = {0};
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(header(rank)), "x.nii"), ErrorCode::corrupt,
                      "offset 40: NIfTI field 'dim[0]'");
  Spec zero;
  zero.dim = {3, 5, 0, 3};
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(header(zero)), "x.nii"), ErrorCode::corrupt,
                      "dim[2]");
  Spec complex;  // complex64: two float32 per voxel
  complex.datatype = 32;
  complex.bitpix = 64;
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(header(complex)), "x.nii"), ErrorCode::unsupported,
                      "offset 70: NIfTI field 'datatype'");
  Spec bits;
  bits.bitpix = 16;
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(header(bits)), "x.nii"), ErrorCode::corrupt,
                      "bitpix");
  Spec off;
  off.vox_offset = 352;
  auto small = header(off);
  const float v = 100.0f;
  std::memcpy(small.data() + 108, &v, 4);
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(small), "x.nii"), ErrorCode::corrupt, "vox_offset");
  Spec six;  // dim[5] holds components (channels); dims 6 and 7 have no meaning here
  six.dim = {6, 2, 2, 2, 1, 1, 2};
  EXPECT_RESOCT_ERROR(parse_nifti_header(bytes(header(six)), "x.nii"), ErrorCode::unsupported,
                      "dim[6]");

  // Whole files: data shorter than the header announces, plain and gzip; a damaged gzip stream.
  auto file = header(good);
  file.resize(file.size() + 59);  // one voxel short of 5x4x3
  test::write_bytes(dir.file("short.nii"), file);
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("short.nii")), ErrorCode::truncated, "short.nii");
  test::write_bytes(dir.file("short.nii.gz"), test::gzip_bytes(file));
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("short.nii.gz")), ErrorCode::truncated, "short.nii.gz");
  file.resize(file.size() + 1);
  auto gz = test::gzip_bytes(file);
  gz.resize(gz.size() / 2);
  test::write_bytes(dir.file("cut.nii.gz"), gz);
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("cut.nii.gz")), ErrorCode::truncated, "cut.nii.gz");
  gz = test::gzip_bytes(file);
  gz[gz.size() / 2] ^= 0xff;
  gz[gz.size() / 2 + 1] ^= 0x55;
  test::write_bytes(dir.file("bad.nii.gz"), gz);
  EXPECT_TRUE(test::throws_error([&] { open_nifti(dir.file("bad.nii.gz")); },
                                 ErrorCode::decompress_failed, "bad.nii.gz") ||
              test::throws_error([&] { open_nifti(dir.file("bad.nii.gz")); }, ErrorCode::truncated,
                                 "bad.nii.gz"));
  test::write_bytes(dir.file("tiny.nii"), {1, 2, 3});
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("tiny.nii")), ErrorCode::truncated, "tiny.nii");
}

/// The decompressed bytes of a .nii.gz, by zlib directly (independent of the reader).
std::vector<std::uint8_t> gunzip(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  std::vector<std::uint8_t> out;
  std::uint8_t buf[1 << 16];
  int n;
  while ((n = gzread(f, buf, sizeof buf)) > 0) out.insert(out.end(), buf, buf + n);
  gzclose(f);
  return out;
}

TEST(NiftiRealData, Colin27T1MatchesTheFileVoxelForVoxel) {
  const std::string path = kTemplates + "ch2better.nii.gz";
  ASSERT_TRUE(std::filesystem::exists(path)) << "install mricron-data (scripts/install-deps.sh)";
  const auto src = open_source(path);
  const VolumeDesc& d = src->volume();
  EXPECT_EQ(d.extent, glm::u64vec3(301, 370, 316));
  EXPECT_EQ(d.spacing, glm::dvec3(0.5));
  EXPECT_EQ(d.type, VoxelType::u8);
  const auto raw = gunzip(path);
  ASSERT_GE(raw.size(), 352u + 301u * 370u * 316u);
  const auto v = level0_values(*src, 0);
  std::size_t differ = 0, nonzero = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    differ += v[i] != double(raw[352 + i]);
    nonzero += raw[352 + i] != 0;
  }
  EXPECT_EQ(differ, 0u);
  // A brain fills a good part of its box: between 10 % and 60 % of the voxels are tissue.
  EXPECT_GT(nonzero, v.size() / 10);
  EXPECT_LT(nonzero, v.size() * 6 / 10);
  // Region metadata is conservative: the whole-volume maximum is the file's maximum.
  std::uint8_t mx = 0;
  for (std::size_t i = 352; i < raw.size(); ++i) mx = std::max(mx, raw[i]);
  EXPECT_EQ(src->region_meta(0, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)}).max, double(mx));
}

TEST(NiftiRealData, T1AndAtlasesStackAsChannels) {
  const std::string t1 = kTemplates + "ch2.nii.gz", aal = kTemplates + "aal.nii.gz",
                    ba = kTemplates + "brodmann.nii.gz";
  const BrickLayout layout{glm::uvec3(32), 1};
  const auto stack = open_source("stack:" + t1 + "+" + aal + "+" + ba, layout);
  ASSERT_EQ(stack->volume().channels, 3u);
  EXPECT_EQ(stack->volume().extent, glm::u64vec3(181, 217, 181));
  const auto atlas = open_source(aal, layout);
  // Channel 1 is the AAL atlas: same bricks at every level, labels 0..116 as its range.
  const auto& h = stack->hierarchy();
  std::vector<std::byte> x(layout.padded_voxels()), y(layout.padded_voxels());
  for (std::uint64_t i = 0; i < h.bricks_per_channel(); ++i) {
    const BrickKey k = h.key_from_linear(1, i);
    stack->read_brick(k, x);
    atlas->read_brick(BrickKey(k.level(), 0, k.brick()), y);
    ASSERT_EQ(x, y) << "brick " << i;
  }
  const auto raw = gunzip(aal);
  std::uint8_t mx = 0;
  for (std::size_t i = 352; i < raw.size(); ++i) mx = std::max(mx, raw[i]);
  EXPECT_EQ(stack->volume().range(1), (ValueRange{0.0, double(mx)}));
  EXPECT_GE(mx, 90);  // AAL has 116 regions (90 cerebral)
  EXPECT_EQ(stack->region_meta(1, Box3{glm::i64vec3(0), glm::i64vec3(181, 217, 181)}).max,
            double(mx));
  const auto mismatched = kTemplates + "ch2better.nii.gz";
  EXPECT_RESOCT_ERROR(open_source("stack:" + t1 + "+" + mismatched, layout),
                      ErrorCode::invalid_argument, "differs");
}

TEST(NiftiRealData, Int16AtlasWithExtensionsAndFloatTemplate) {
  // inia19-NeuroMaps: int16 with header extensions (vox_offset 32976), kept as u16 + 32768 (two
  // bytes per voxel, every value exact).
  const std::string path = kTemplates + "inia19-NeuroMaps.nii.gz";
  const auto src = open_source(path);
  EXPECT_EQ(src->volume().type, VoxelType::u16);
  EXPECT_EQ(src->volume().data_type, DataType::i16);
  EXPECT_EQ(src->volume().extent, glm::u64vec3(168, 206, 128));
  const auto raw = gunzip(path);
  const auto v = level0_values(*src, 0);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::int16_t s;
    std::memcpy(&s, raw.data() + 32976 + 2 * i, 2);
    differ += v[i] - 32768.0 != double(s);
  }
  EXPECT_EQ(differ, 0u);
  const auto t1 = open_source(kTemplates + "inia19-t1-brain.nii.gz");
  EXPECT_EQ(t1->volume().type, VoxelType::f32);
  EXPECT_GT(t1->volume().range(0).hi, t1->volume().range(0).lo);
}

}  // namespace
