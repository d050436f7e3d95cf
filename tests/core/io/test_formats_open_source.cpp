// open_source / detect_source_kind over the file formats: each form is recognised (by content for
// directories and stores, by extension for files) and unknown forms fail naming the path and
// listing the accepted forms.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/open_source.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
using test::TempDir;

namespace {

TEST(FormatsOpenSource, KindsByPrefixContentAndExtension) {
  TempDir dir;
  auto touch = [&](const std::string& name) {
    std::filesystem::create_directories(std::filesystem::path(dir.file(name)).parent_path());
    test::write_bytes(dir.file(name), {'x'});
    return dir.file(name);
  };
  EXPECT_EQ(detect_source_kind("procedural:tubes"), SourceKind::procedural);
  EXPECT_EQ(detect_source_kind("stack:a+b"), SourceKind::stack);
  EXPECT_EQ(detect_source_kind(touch("a.NII.GZ")), SourceKind::nifti);
  EXPECT_EQ(detect_source_kind(touch("a.nii")), SourceKind::nifti);
  EXPECT_EQ(detect_source_kind(touch("a.nhdr")), SourceKind::nrrd);
  EXPECT_EQ(detect_source_kind(touch("a.Nrrd")), SourceKind::nrrd);
  EXPECT_EQ(detect_source_kind(touch("a.tiff")), SourceKind::tiff);
  EXPECT_EQ(detect_source_kind(touch("a.raw")), SourceKind::unknown);
  touch("z.zarr/.zattrs");
  EXPECT_EQ(detect_source_kind(dir.file("z.zarr")), SourceKind::ome_zarr);
  touch("t/one.TIF");
  EXPECT_EQ(detect_source_kind(dir.file("t")), SourceKind::tiff);
  touch("e/readme.txt");
  EXPECT_EQ(detect_source_kind(dir.file("e")), SourceKind::unknown);
  EXPECT_EQ(detect_source_kind(dir.file("missing.nii")), SourceKind::unknown);
  EXPECT_EQ(to_string(SourceKind::ome_zarr), "ome-zarr");
  EXPECT_EQ(to_string(SourceKind::brick_store), "store");

  EXPECT_RESOCT_ERROR(open_source(dir.file("e")), ErrorCode::invalid_argument,
                      "neither an OME-Zarr image");
  EXPECT_RESOCT_ERROR(open_source(dir.file("a.raw")), ErrorCode::invalid_argument, "a.raw");
  EXPECT_RESOCT_ERROR(open_source(dir.file("a.raw")), ErrorCode::invalid_argument,
                      std::string(kSourceSpecForms));
  // A file named like a format but holding something else fails in that format's reader.
  EXPECT_RESOCT_ERROR(open_source(dir.file("a.nii")), ErrorCode::truncated, "a.nii");
  EXPECT_RESOCT_ERROR(open_source("stack:"), ErrorCode::invalid_argument, "empty part");
  EXPECT_RESOCT_ERROR(open_source("stack:procedural:sphere:16x16x16+"), ErrorCode::invalid_argument,
                      "empty part");
}

TEST(FormatsOpenSource, StackOfProceduralSourcesConcatenatesChannels) {
  const auto s = open_source("stack:procedural:sphere:16x16x16+procedural:ramp:16x16x16",
                             BrickLayout{glm::uvec3(8), 1});
  ASSERT_EQ(s->volume().channels, 2u);
  const auto ramp = open_source("procedural:ramp:16x16x16", BrickLayout{glm::uvec3(8), 1});
  std::vector<std::byte> a(s->hierarchy().layout().padded_voxels() * 4), b(a.size());
  s->read_brick(BrickKey(0, 1, {1, 0, 1}), a);
  ramp->read_brick(BrickKey(0, 0, {1, 0, 1}), b);
  EXPECT_EQ(a, b);
  EXPECT_EQ(s->volume().range(1), ramp->volume().range(0));
  EXPECT_EQ(s->region_meta(1, Box3{{0, 0, 0}, {16, 16, 16}}),
            ramp->region_meta(0, Box3{{0, 0, 0}, {16, 16, 16}}));
  EXPECT_RESOCT_ERROR(open_source("stack:procedural:sphere:16x16x16+procedural:ramp:8x16x16"),
                      ErrorCode::invalid_argument, "differs");
}

}  // namespace
