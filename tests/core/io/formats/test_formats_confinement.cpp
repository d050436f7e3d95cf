// Files may only reach what they are allowed to: a file that names other files (a detached NRRD
// header's data file, the keys of a zarr directory, the entries of a TIFF directory, the parts
// of a channel stack) is confined to its own directory. Absolute names, '..' and symbolic links
// leading out are refused with an Error naming the referring file and the offending path;
// links that stay inside keep working.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/io/storage/byte_store.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/nrrd.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "resoct/io/formats/tiff_stack.hpp"
#include "resoct/io/open_source.hpp"
#include "support/expect_error.hpp"
#include "support/level0_values.hpp"
#include "support/tiff_writer.hpp"

using namespace resoct;
using test::TempDir;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> text_bytes(const std::string& s) {
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

/// A detached header for 4 uchar samples in `data_file`.
void write_nhdr(const std::string& path, const std::string& data_file) {
  test::write_bytes(path, text_bytes("NRRD0004\ntype: uchar\ndimension: 1\nsizes: 4\nencoding: "
                                     "raw\ndata file: " +
                                     data_file + "\n"));
}

const std::vector<std::uint8_t> kSamples = {1, 2, 3, 4};

/// Both the header and the offending name must be in the message, with the refusal's code.
void expect_refused(const std::string& header, const std::string& name, const std::string& why) {
  SCOPED_TRACE(name);
  EXPECT_RESOCT_ERROR(open_nrrd(header), ErrorCode::invalid_argument,
                      header + ": NRRD field 'data file' '" + name + "' " + why);
}

TEST(Confinement, NrrdDataFileOutsideTheHeaderDirectoryIsRefused) {
  TempDir outside, dir;
  test::write_bytes(outside.file("secret.raw"), kSamples);
  fs::create_directories(dir.path() / "hdr");
  const std::string h = dir.file("hdr/vol.nhdr");
  test::write_bytes(dir.file("beside.raw"), kSamples);

  write_nhdr(h, "/etc/passwd");
  expect_refused(h, "/etc/passwd", "is absolute");
  write_nhdr(h, outside.file("secret.raw"));
  expect_refused(h, outside.file("secret.raw"), "is absolute");
  write_nhdr(h, "../beside.raw");  // exists, one level up
  expect_refused(h, "../beside.raw", "has a '..' component");
  write_nhdr(h, "sub/../../beside.raw");
  expect_refused(h, "sub/../../beside.raw", "has a '..' component");

  // Symbolic links: to a file outside, and a directory leading outside.
  fs::create_symlink(outside.file("secret.raw"), dir.path() / "hdr" / "link.raw");
  write_nhdr(h, "link.raw");
  expect_refused(h, "link.raw", "resolves to ");
  fs::create_directory_symlink(outside.path(), dir.path() / "hdr" / "elsewhere");
  write_nhdr(h, "elsewhere/secret.raw");
  expect_refused(h, "elsewhere/secret.raw", "resolves to ");
  // The resolved target is named too, so the user sees where the link led.
  EXPECT_RESOCT_ERROR(open_nrrd(h), ErrorCode::invalid_argument,
                      fs::canonical(outside.file("secret.raw")).string() + ", which is not below ");
  // The directory itself is not a data file.
  write_nhdr(h, ".");
  expect_refused(h, ".", "resolves to ");
}

TEST(Confinement, NrrdDataFileBelowTheHeaderDirectoryIsRead) {
  TempDir dir;
  fs::create_directories(dir.path() / "data");
  test::write_bytes(dir.file("data/vol.raw"), kSamples);
  fs::create_symlink("data/vol.raw", dir.path() / "alias.raw");  // a link that stays inside
  for (const std::string name : {"data/vol.raw", "./data/vol.raw", "alias.raw"}) {
    SCOPED_TRACE(name);
    write_nhdr(dir.file("vol.nhdr"), name);
    const auto src = open_nrrd(dir.file("vol.nhdr"), BrickLayout{glm::uvec3(4), 1});
    EXPECT_EQ(level0_values(*src, 0), (std::vector<double>{1, 2, 3, 4}));
  }
  // The header itself may be reached through a link from anywhere: only what it names is
  // confined, to the directory of the path it was opened by.
  TempDir other;
  fs::create_symlink(dir.file("vol.nhdr"), other.path() / "via.nhdr");
  test::write_bytes(other.file("data.raw"), kSamples);
  write_nhdr(dir.file("vol.nhdr"), "data.raw");
  EXPECT_EQ(level0_values(*open_nrrd(other.file("via.nhdr")), 0),
            (std::vector<double>{1, 2, 3, 4}));
}

TEST(Confinement, ChannelStackPartsKeepTheirFormatsRule) {
  TempDir outside, dir;
  test::write_bytes(outside.file("secret.raw"), kSamples);
  test::write_bytes(dir.file("good.raw"), kSamples);
  write_nhdr(dir.file("good.nhdr"), "good.raw");
  write_nhdr(dir.file("evil.nhdr"), outside.file("secret.raw"));
  const auto ok = open_source("stack:" + dir.file("good.nhdr") + "+" + dir.file("good.nhdr"));
  EXPECT_EQ(ok->volume().channels, 2u);
  EXPECT_RESOCT_ERROR(open_source("stack:" + dir.file("good.nhdr") + "+" + dir.file("evil.nhdr")),
                      ErrorCode::invalid_argument,
                      dir.file("evil.nhdr") + ": NRRD field 'data file' '" +
                          outside.file("secret.raw") + "' is absolute");
}

/// A one-array zarr store: 4x4x4 u8, one uncompressed chunk.
void write_zarr(const fs::path& root) {
  fs::create_directories(root);
  test::write_bytes((root / ".zarray").string(),
                    text_bytes(R"({"zarr_format": 2, "shape": [4, 4, 4], "chunks": [4, 4, 4],
                                   "dtype": "|u1", "order": "C", "compressor": null,
                                   "fill_value": 0, "filters": null})"));
  std::vector<std::uint8_t> chunk(64);
  for (std::size_t i = 0; i < chunk.size(); ++i) chunk[i] = std::uint8_t(i);
  test::write_bytes((root / "0.0.0").string(), chunk);
}

TEST(Confinement, ZarrObjectsBehindLinksLeadingOutAreRefused) {
  TempDir outside, dir;
  write_zarr(outside.path() / "real.zarr");
  const fs::path z = dir.path() / "img.zarr";
  write_zarr(z);
  EXPECT_EQ(level0_values(*open_ome_zarr(z.string()), 0).at(63), 63.0);

  // A chunk that is a link to a file outside the store.
  fs::remove(z / "0.0.0");
  fs::create_symlink(outside.path() / "real.zarr" / "0.0.0", z / "0.0.0");
  const auto store = open_directory_store(z.string());
  EXPECT_RESOCT_ERROR((void)store->get("0.0.0", 1 << 20), ErrorCode::invalid_argument,
                      z.string() + ": store key '0.0.0' resolves to ");
  EXPECT_RESOCT_ERROR((void)store->get_range("0.0.0", 0, 4), ErrorCode::invalid_argument,
                      "store key '0.0.0'");
  EXPECT_RESOCT_ERROR(open_ome_zarr(z.string()), ErrorCode::invalid_argument, "store key '0.0.0'");

  // Metadata behind a link, e.g. to a system file.
  fs::remove(z / ".zarray");
  fs::create_symlink("/etc/passwd", z / ".zarray");
  EXPECT_RESOCT_ERROR(open_ome_zarr(z.string()), ErrorCode::invalid_argument,
                      "store key '.zarray' resolves to /etc/passwd");

  // A whole level directory leading out.
  TempDir levels;
  const fs::path m = levels.path() / "m.zarr";
  fs::create_directories(m);
  fs::create_directory_symlink(outside.path() / "real.zarr", m / "0");
  const auto ms = open_directory_store(m.string());
  EXPECT_RESOCT_ERROR((void)ms->get("0/.zarray", 1 << 20), ErrorCode::invalid_argument,
                      "store key '0/.zarray'");
  // A dangling link outside stays what a missing object is: absent (fill value for a chunk).
  fs::create_symlink(outside.path() / "nothing", m / "1.0.0");
  EXPECT_FALSE(ms->get("1.0.0", 1 << 20).has_value());
}

TEST(Confinement, ZarrLinksWithinTheStoreAreRead) {
  TempDir dir;
  const fs::path z = dir.path() / "img.zarr";
  write_zarr(z);
  fs::create_directories(z / "blobs");
  fs::rename(z / "0.0.0", z / "blobs" / "c0");
  fs::create_symlink("blobs/c0", z / "0.0.0");
  const auto v = level0_values(*open_ome_zarr(z.string()), 0);
  for (std::size_t i = 0; i < v.size(); ++i) ASSERT_EQ(v[i], double(i));
  // The store's root may itself be reached through a link.
  fs::create_directory_symlink(z, dir.path() / "alias.zarr");
  EXPECT_EQ(level0_values(*open_ome_zarr((dir.path() / "alias.zarr").string()), 0), v);
}

std::vector<std::uint8_t> tiff_page(double value) {
  test::Page p;
  p.values.assign(std::size_t(p.width) * p.height, value);
  test::TiffWriter w(false);
  w.page(p);
  return w.bytes();
}

TEST(Confinement, TiffDirectoryEntriesLeadingOutAreRefused) {
  TempDir outside, dir;
  test::write_bytes(outside.file("secret.tif"), tiff_page(9));
  test::write_bytes(dir.file("a.tif"), tiff_page(1));
  fs::create_symlink(outside.file("secret.tif"), dir.path() / "b.tif");
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.path().string()), ErrorCode::invalid_argument,
                      dir.path().string() + ": entry '" + dir.file("b.tif") + "' resolves to " +
                          fs::canonical(outside.file("secret.tif")).string());
  EXPECT_RESOCT_ERROR(open_source(dir.path().string()), ErrorCode::invalid_argument,
                      "entry '" + dir.file("b.tif") + "'");
  // A link to a slice inside the directory is an ordinary slice, in the order of its name.
  fs::remove(dir.path() / "b.tif");
  fs::create_directories(dir.path() / "sub");
  test::write_bytes(dir.file("sub/z.tif"), tiff_page(2));
  fs::create_symlink("sub/z.tif", dir.path() / "b.tif");
  test::write_bytes(dir.file("c.tif"), tiff_page(3));
  const auto src = open_tiff_stack(dir.path().string(), BrickLayout{glm::uvec3(4), 1});
  ASSERT_EQ(src->volume().extent.z, 3u);
  const auto v = level0_values(*src, 0);
  const std::size_t slice = 7 * 5;
  EXPECT_EQ(v[0], 1.0);
  EXPECT_EQ(v[slice], 2.0);
  EXPECT_EQ(v[2 * slice], 3.0);
  // The file or directory the user names may itself be a link.
  TempDir other;
  fs::create_directory_symlink(dir.path(), other.path() / "stack");
  EXPECT_EQ(open_tiff_stack((other.path() / "stack").string())->volume().extent.z, 3u);
}

}  // namespace
