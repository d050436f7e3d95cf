// NIfTI as scanners write it: NIfTI-2 (every datatype, both byte orders, plain and gzip), two-file
// pairs (.hdr + .img, gzipped or not, opened by either file) and Analyze 7.5, the time axis
// (dim[4]) as timepoints and components (dim[5]) as channels, placement from the sform / qform
// (flips and permutations reorder voxels; spacing, origin), and damaged input. Headers are written
// from the specs' layouts by support/nifti_writer.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/nifti.hpp"
#include "resoct/io/open_source.hpp"
#include "support/expect_error.hpp"
#include "support/gzip_bytes.hpp"
#include "support/level0_values.hpp"
#include "support/nifti_writer.hpp"

using namespace resoct;
using test::append_value;
using test::NiftiImageSpec;
using test::TempDir;

namespace {

const BrickLayout kLayout{glm::uvec3(4), 1};

std::vector<std::byte> as_bytes(const std::vector<std::uint8_t>& v) {
  return {reinterpret_cast<const std::byte*>(v.data()),
          reinterpret_cast<const std::byte*>(v.data()) + v.size()};
}

/// A u8 image whose voxel n (in file order) holds n + 1 + 30 * volume (volume: t, then c).
std::vector<std::uint8_t> u8_image(const NiftiImageSpec& s, std::uint64_t volumes) {
  auto b = test::nifti_header_bytes(s);
  const std::uint64_t n = std::uint64_t(s.dim[1] * s.dim[2] * s.dim[3]);
  for (std::uint64_t v = 0; v < volumes; ++v) {
    for (std::uint64_t i = 0; i < n; ++i) b.push_back(std::uint8_t(i + 1 + 30 * v));
  }
  return b;
}

std::vector<double> expected_u8(std::uint64_t n, std::uint64_t volume) {
  std::vector<double> v;
  for (std::uint64_t i = 0; i < n; ++i) v.push_back(double(i + 1 + 30 * volume));
  return v;
}

TEST(Nifti2, EveryDatatypeBothByteOrdersPlainAndGzip) {
  TempDir dir;
  for (const auto [datatype, bitpix] : {std::pair<std::int16_t, std::int16_t>{2, 8},
                                        {256, 8},
                                        {4, 16},
                                        {512, 16},
                                        {8, 32},
                                        {768, 32},
                                        {16, 32},
                                        {64, 64}}) {
    for (bool big : {false, true}) {
      for (bool gz : {false, true}) {
        SCOPED_TRACE(std::to_string(datatype) + (big ? " big" : " little") + (gz ? " gz" : ""));
        NiftiImageSpec s;
        s.version = 2;
        s.big = big;
        s.datatype = datatype;
        s.bitpix = bitpix;
        s.pixdim[1] = 0.7, s.pixdim[2] = 0.8, s.pixdim[3] = 2.5;
        auto b = test::nifti_header_bytes(s);
        std::vector<double> want;
        for (int i = 0; i < 24; ++i) {
          double v = double(i * 7 % 100);
          switch (datatype) {
            case 256: v -= 50; break;
            case 4: v = v * 61 - 3000; break;
            case 512: v *= 600; break;
            case 8: v = v * 99991 - 5000000; break;
            case 768: v = v * 99991 + 3; break;
            case 16:
            case 64: v = v * 0.25 - 4; break;
          }
          want.push_back(v);
          switch (datatype) {
            case 2: append_value(b, std::uint8_t(v), big); break;
            case 256: append_value(b, std::int8_t(v), big); break;
            case 4: append_value(b, std::int16_t(v), big); break;
            case 512: append_value(b, std::uint16_t(v), big); break;
            case 8: append_value(b, std::int32_t(v), big); break;
            case 768: append_value(b, std::uint32_t(v), big); break;
            case 16: append_value(b, float(v), big); break;
            case 64: append_value(b, v, big); break;
          }
        }
        const std::string path = dir.file(gz ? "v2.nii.gz" : "v2.nii");
        test::write_bytes(path, gz ? test::gzip_bytes(b) : b);
        const NiftiHeader h = read_nifti_header(path);
        EXPECT_EQ(h.version, 2);
        EXPECT_EQ(h.form, NiftiForm::single);
        const auto src = open_source(path, kLayout);
        const VolumeDesc& d = src->volume();
        EXPECT_EQ(d.extent, glm::u64vec3(4, 3, 2));
        EXPECT_NEAR(d.spacing.x, 0.7, 1e-12);
        EXPECT_NEAR(d.spacing.z, 2.5, 1e-12);
        std::vector<double> got = level0_values(*src, 0);
        for (double& v : got) v -= d.value_offset();
        EXPECT_EQ(got, want);
      }
    }
  }
}

TEST(NiftiPairs, HdrImgPairsAndAnalyzeOpenByEitherFile) {
  TempDir dir;
  struct Case {
    int version;
    const char* magic;
    bool hdr_gz, img_gz;
  };
  for (const Case c :
       {Case{1, "ni1", false, false}, Case{1, "ni1", true, true}, Case{2, "ni2", false, true},
        Case{2, "ni2", true, false}, Case{1, "none", false, false}, Case{1, "none", true, true}}) {
    for (bool big : {false, true}) {
      SCOPED_TRACE(std::string(c.magic) + (c.hdr_gz ? " hdr.gz" : "") +
                   (c.img_gz ? " img.gz" : "") + (big ? " big" : ""));
      const std::string stem = std::string("p") + c.magic + std::to_string(c.hdr_gz) +
                               std::to_string(c.img_gz) + std::to_string(big);
      NiftiImageSpec s;
      s.version = c.version;
      s.magic = c.magic;
      s.big = big;
      s.datatype = 4, s.bitpix = 16;
      s.pixdim[1] = 2, s.pixdim[2] = 3, s.pixdim[3] = 4;
      // Analyze has neither scaling nor a world map: these must be ignored there.
      s.slope = 2, s.inter = 1, s.sform = 1;
      s.srow[0][0] = -2, s.srow[1][1] = 3, s.srow[2][2] = 4;
      std::vector<std::uint8_t> img(3, 0);  // vox_offset 3 in the .img
      std::vector<double> want;
      for (int i = 0; i < 24; ++i) {
        append_value(img, std::int16_t(i * 10 - 100), big);
        want.push_back(i * 10 - 100);
      }
      auto hs = s;
      hs.vox_offset = 3;
      const auto header3 = test::nifti_header_bytes(hs);
      const std::string hdr = dir.file(stem + (c.hdr_gz ? ".hdr.gz" : ".hdr"));
      const std::string dat = dir.file(stem + (c.img_gz ? ".img.gz" : ".img"));
      test::write_bytes(hdr, c.hdr_gz ? test::gzip_bytes(header3) : header3);
      test::write_bytes(dat, c.img_gz ? test::gzip_bytes(img) : img);
      const bool analyze = std::string(c.magic) == "none";
      for (const std::string& open : {hdr, dat}) {
        const auto src = open_source(open, kLayout);
        const VolumeDesc& d = src->volume();
        EXPECT_EQ(d.extent, glm::u64vec3(4, 3, 2));
        EXPECT_EQ(d.spacing, glm::dvec3(2, 3, 4));
        std::vector<double> got = level0_values(*src, 0);
        if (analyze) {
          EXPECT_EQ(d.data_type, DataType::i16);
          for (double& v : got) v -= d.value_offset();
          EXPECT_EQ(got, want);
          EXPECT_EQ(d.origin, glm::dvec3(-1, -1.5, -2));  // voxel 0 centred at 0
        } else {
          // Scaled by slope 2, inter 1, and the sform flips x.
          EXPECT_EQ(d.type, VoxelType::f32);
          ASSERT_EQ(got.size(), 24u);
          for (int i = 0; i < 24; ++i) {
            const int x = i % 4, yz = i / 4;
            EXPECT_EQ(got[std::size_t(i)], 2 * want[std::size_t(yz * 4 + 3 - x)] + 1);
          }
          EXPECT_EQ(d.origin, glm::dvec3(-7, -1.5, -2));
        }
      }
    }
  }
  // A missing partner names what was looked for.
  NiftiImageSpec s;
  s.magic = "ni1";
  test::write_bytes(dir.file("alone.hdr"), test::nifti_header_bytes(s));
  EXPECT_RESOCT_ERROR(open_source(dir.file("alone.hdr")), ErrorCode::io, "alone.img");
  test::write_bytes(dir.file("orphan.img"), std::vector<std::uint8_t>(24, 1));
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("orphan.img")), ErrorCode::io, "orphan.hdr");
  // A short .img, a single-file header in a .hdr, a pair header in a .nii.
  test::write_bytes(dir.file("short.hdr"), test::nifti_header_bytes(s));
  test::write_bytes(dir.file("short.img"), std::vector<std::uint8_t>(23, 1));
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("short.hdr")), ErrorCode::truncated, "short.img");
  NiftiImageSpec single;
  test::write_bytes(dir.file("single.hdr"), u8_image(single, 1));
  test::write_bytes(dir.file("single.img"), std::vector<std::uint8_t>(24, 1));
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("single.hdr")), ErrorCode::invalid_argument,
                      "offset 344");
  std::vector<std::uint8_t> pair_in_nii = test::nifti_header_bytes(s);
  pair_in_nii.resize(pair_in_nii.size() + 28, 1);
  test::write_bytes(dir.file("pair.nii"), pair_in_nii);
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("pair.nii")), ErrorCode::invalid_argument, "\"ni1\"");
}

TEST(NiftiTime, FourthDimensionIsTimeAndFifthIsComponents) {
  TempDir dir;
  for (int version : {1, 2}) {
    for (bool gz : {false, true}) {
      SCOPED_TRACE(std::to_string(version) + (gz ? " gz" : ""));
      NiftiImageSpec s;
      s.version = version;
      s.dim = {4, 4, 3, 2, 3};  // three timepoints
      const std::string path = dir.file(std::string("t") + (gz ? ".nii.gz" : ".nii"));
      const auto file = u8_image(s, 3);
      test::write_bytes(path, gz ? test::gzip_bytes(file) : file);
      EXPECT_EQ(read_nifti_header(path).timepoints(), 3u);
      for (std::uint64_t t = 0; t < 3; ++t) {
        SourceOptions o;
        o.nifti.timepoint = t;
        const auto src = open_source(path, kLayout, o);
        EXPECT_EQ(src->volume().channels, 1u);
        EXPECT_EQ(level0_values(*src, 0), expected_u8(24, t));
      }
      EXPECT_RESOCT_ERROR(open_nifti(path, kLayout, NiftiOptions{3}), ErrorCode::invalid_argument,
                          "parameter 'timepoint': " + path +
                              ": 3 is out of range: the image "
                              "has 3 timepoint(s)");
      // The series as the renderer switches through it (BrickSource::open_timepoint): every
      // timepoint's voxels, with the value ranges of the timepoint opened first, so that one
      // transfer function maps them alike (source_at_timepoint checks the hierarchies agree).
      const std::shared_ptr<const BrickSource> first = open_nifti(path, kLayout, NiftiOptions{1});
      EXPECT_EQ(first->timepoints(), 3u);
      EXPECT_EQ(first->timepoint(), 1u);
      for (std::uint32_t t = 0; t < 3; ++t) {
        const auto at = source_at_timepoint(first, t);
        EXPECT_EQ(at->timepoint(), t);
        EXPECT_EQ(at->volume(), first->volume());
        EXPECT_EQ(level0_values(*at, 0), expected_u8(24, t));
      }
      EXPECT_NE(open_nifti(path, kLayout, NiftiOptions{0})->volume().ranges,
                first->volume().ranges);  // each timepoint alone has its own data range

      // dim[5] = 2 components of 3 timepoints: channel c of timepoint t is volume c * 3 + t.
      s.dim = {5, 4, 3, 2, 3, 2};
      const std::string p5 = dir.file(std::string("c") + (gz ? ".nii.gz" : ".nii"));
      const auto f5 = u8_image(s, 6);
      test::write_bytes(p5, gz ? test::gzip_bytes(f5) : f5);
      for (std::uint64_t t = 0; t < 3; ++t) {
        const auto src = open_nifti(p5, kLayout, NiftiOptions{t});
        ASSERT_EQ(src->volume().channels, 2u);
        EXPECT_EQ(level0_values(*src, 0), expected_u8(24, t));
        EXPECT_EQ(level0_values(*src, 1), expected_u8(24, 3 + t));
      }
    }
  }
}

/// The served value at (x, y, z) of a 4x3x2 u8 image written by u8_image.
double served(const std::vector<double>& v, glm::u64vec3 e, int x, int y, int z) {
  return v[std::size_t((std::uint64_t(z) * e.y + std::uint64_t(y)) * e.x + std::uint64_t(x))];
}

TEST(NiftiPlacement, SformAndQformFlipsAndPermutationsReorderVoxels) {
  TempDir dir;
  // Stored voxel (i, j, k) of the 4x3x2 image holds 1 + i + 4 j + 12 k.
  auto stored = [](int i, int j, int k) { return double(1 + i + 4 * j + 12 * k); };
  for (int version : {1, 2}) {
    SCOPED_TRACE(version);
    // sform: i runs along -x (0.5 mm), j along +z (2 mm), k along -y (3 mm); origin (10, 20, 30).
    NiftiImageSpec s;
    s.version = version;
    s.sform = 2;
    s.qform = 1;  // ignored: the sform wins
    s.srow[0][0] = -0.5, s.srow[0][3] = 10;
    s.srow[2][1] = 2, s.srow[2][3] = 30;
    s.srow[1][2] = -3, s.srow[1][3] = 20;
    test::write_bytes(dir.file("s.nii"), u8_image(s, 1));
    const auto src = open_nifti(dir.file("s.nii"), kLayout);
    const VolumeDesc& d = src->volume();
    // Served x = stored i reversed, y = stored k reversed, z = stored j.
    EXPECT_EQ(d.extent, glm::u64vec3(4, 2, 3));
    EXPECT_EQ(d.spacing, glm::dvec3(0.5, 3, 2));
    // Served voxel 0 is stored (3, 0, 1): centre (10 - 1.5, 20 - 3, 30), minus half a voxel.
    EXPECT_EQ(d.origin, glm::dvec3(8.5 - 0.25, 17 - 1.5, 30 - 1));
    const auto v = level0_values(*src, 0);
    for (int x = 0; x < 4; ++x)
      for (int y = 0; y < 2; ++y)
        for (int z = 0; z < 3; ++z)
          EXPECT_EQ(served(v, d.extent, x, y, z), stored(3 - x, z, 1 - y));

    // qform: 180 degrees about z (quatern d = 1: x and y negated), qfac -1 (k negated).
    NiftiImageSpec q;
    q.version = version;
    q.qform = 1;
    q.quatern[2] = 1;
    q.pixdim[0] = -1, q.pixdim[1] = 1, q.pixdim[2] = 2, q.pixdim[3] = 3;
    q.qoffset[0] = 5, q.qoffset[1] = 6, q.qoffset[2] = 7;
    test::write_bytes(dir.file("q.nii"), u8_image(q, 1));
    const auto qs = open_nifti(dir.file("q.nii"), kLayout);
    const VolumeDesc& qd = qs->volume();
    EXPECT_EQ(qd.extent, glm::u64vec3(4, 3, 2));
    EXPECT_EQ(qd.spacing, glm::dvec3(1, 2, 3));
    EXPECT_EQ(qd.origin, glm::dvec3(5 - 3 - 0.5, 6 - 4 - 1, 7 - 3 - 1.5));
    const auto qv = level0_values(*qs, 0);
    for (int x = 0; x < 4; ++x)
      for (int y = 0; y < 3; ++y)
        for (int z = 0; z < 2; ++z) {
          EXPECT_EQ(served(qv, qd.extent, x, y, z), stored(3 - x, 2 - y, 1 - z));
        }

    // No sform / qform: pixdim spacing, index order, voxel 0 centred at the world origin.
    NiftiImageSpec plain;
    plain.version = version;
    plain.pixdim[1] = 2, plain.pixdim[2] = 2, plain.pixdim[3] = 2;
    test::write_bytes(dir.file("p.nii"), u8_image(plain, 1));
    const auto ps = open_nifti(dir.file("p.nii"), kLayout);
    EXPECT_EQ(ps->volume().origin, glm::dvec3(-1));
    EXPECT_EQ(level0_values(*ps, 0), expected_u8(24, 0));
  }
}

TEST(NiftiPlacement, SameGridDifferentStorageOrderStacksAligned) {
  TempDir dir;
  // a.nii stores RAS order; b.nii the same world grid stored x-reversed with z first.
  NiftiImageSpec a;
  a.sform = 1;
  a.srow[0][0] = 1, a.srow[1][1] = 1, a.srow[2][2] = 1;
  test::write_bytes(dir.file("a.nii"), u8_image(a, 1));
  NiftiImageSpec b;
  b.dim = {3, 2, 4, 3};  // i = z, j = x (reversed), k = y
  b.sform = 1;
  b.srow[2][0] = 1, b.srow[0][1] = -1, b.srow[1][2] = 1;
  b.srow[0][3] = 3;
  auto fb = test::nifti_header_bytes(b);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 2; ++i) fb.push_back(std::uint8_t(1 + (3 - j) + 4 * k + 12 * i));
  test::write_bytes(dir.file("b.nii"), fb);
  const auto stack = open_source("stack:" + dir.file("a.nii") + "+" + dir.file("b.nii"), kLayout);
  ASSERT_EQ(stack->volume().channels, 2u);
  EXPECT_EQ(stack->volume().origin, glm::dvec3(-0.5));
  // Both serve the same voxels in the same places (the stack reads its parts' bricks).
  EXPECT_EQ(level0_values(*open_source(dir.file("a.nii"), kLayout), 0), expected_u8(24, 0));
  EXPECT_EQ(level0_values(*open_source(dir.file("b.nii"), kLayout), 0), expected_u8(24, 0));
  EXPECT_EQ(open_source(dir.file("b.nii"), kLayout)->volume(),
            open_source(dir.file("a.nii"), kLayout)->volume());
  // Same extent, another place: refused, naming the origins.
  NiftiImageSpec c = a;
  c.srow[0][3] = 100;
  test::write_bytes(dir.file("c.nii"), u8_image(c, 1));
  EXPECT_RESOCT_ERROR(open_source("stack:" + dir.file("a.nii") + "+" + dir.file("c.nii"), kLayout),
                      ErrorCode::invalid_argument, "origin");
}

TEST(NiftiDamaged, TruncatedAbsurdAndMismatched) {
  TempDir dir;
  NiftiImageSpec s;
  s.version = 2;
  const auto h = as_bytes(test::nifti_header_bytes(s));
  EXPECT_RESOCT_ERROR(parse_nifti_header(std::span(h).first(400), "x.nii"), ErrorCode::truncated,
                      "x.nii: offset 400: NIfTI-2 header needs 540 bytes");
  auto bad_magic = h;
  bad_magic[8] = std::byte{'\n'};  // "\r\n" turned into "\n\n" by a text-mode copy
  EXPECT_RESOCT_ERROR(parse_nifti_header(bad_magic, "x.nii"), ErrorCode::bad_magic, "offset 4");
  NiftiImageSpec absurd = s;
  absurd.dim = {3, std::int64_t(1) << 40, std::int64_t(1) << 40, 1 << 20};
  EXPECT_RESOCT_ERROR(parse_nifti_header(as_bytes(test::nifti_header_bytes(absurd)), "x.nii"),
                      ErrorCode::overflow, "offset 16");
  NiftiImageSpec negative = s;
  negative.dim = {3, 4, -3, 2};
  EXPECT_RESOCT_ERROR(parse_nifti_header(as_bytes(test::nifti_header_bytes(negative)), "x.nii"),
                      ErrorCode::corrupt, "offset 32: NIfTI field 'dim[2]'");
  NiftiImageSpec inside = s;
  inside.vox_offset = 100;
  EXPECT_RESOCT_ERROR(parse_nifti_header(as_bytes(test::nifti_header_bytes(inside)), "x.nii"),
                      ErrorCode::corrupt, "offset 168: NIfTI field 'vox_offset'");
  NiftiImageSpec many = s;
  many.dim = {5, 2, 2, 2, 1, 300};
  EXPECT_RESOCT_ERROR(parse_nifti_header(as_bytes(test::nifti_header_bytes(many)), "x.nii"),
                      ErrorCode::unsupported, "dim[5]");
  NiftiImageSpec six = s;
  six.dim = {6, 2, 2, 2, 1, 1, 2};
  EXPECT_RESOCT_ERROR(parse_nifti_header(as_bytes(test::nifti_header_bytes(six)), "x.nii"),
                      ErrorCode::unsupported, "dim[6]");
  // Large announced sizes in a small file: refused before anything that size is allocated.
  NiftiImageSpec big = s;
  big.dim = {4, 1024, 1024, 1024, 1024};
  auto fb = test::nifti_header_bytes(big);
  fb.resize(fb.size() + 100);
  test::write_bytes(dir.file("big.nii"), fb);
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("big.nii"), kLayout, NiftiOptions{5}),
                      ErrorCode::truncated, "big.nii");
  test::write_bytes(dir.file("big.nii.gz"), test::gzip_bytes(fb));
  EXPECT_RESOCT_ERROR(open_nifti(dir.file("big.nii.gz"), kLayout, NiftiOptions{5}),
                      ErrorCode::truncated, "big.nii.gz");
}

}  // namespace
