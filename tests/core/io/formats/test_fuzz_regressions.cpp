// Crashes the fuzzers found (fuzz/regressions/), each pinned to the resoct::Error it must now
// raise. The replay tests (fuzz_replay.*) only assert "no crash"; these also fix the error class
// and that the message names the file, so a later change cannot turn the fix into another
// failure mode unnoticed.

#include <gtest/gtest.h>

#include <string>

#include "resoct/io/formats/nrrd.hpp"
#include "resoct/io/formats/tiff_stack.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/scene/scene.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

std::string regression(const std::string& target, const std::string& name) {
  return std::string(RESOCT_SOURCE_DIR) + "/fuzz/regressions/" + target + "/" + name;
}

}  // namespace

TEST(FuzzRegressions, PngHeaderAnnouncingMorePixelsThanTheFileHoldsIsCorrupt) {
  // 83 bytes announcing 30000x30000 pixels: read_png allocated and cleared 3.5 GB before
  // libpng found the data missing (or threw std::bad_alloc under a memory limit).
  const std::string path = regression("png", "ihdr-30000x30000-in-83-bytes.png");
  EXPECT_RESOCT_ERROR(read_png(path), ErrorCode::corrupt, "30000x30000 image cannot be stored");
  EXPECT_RESOCT_ERROR(read_png(path), ErrorCode::corrupt, path);
}

TEST(FuzzRegressions, NrrdGzipAnnouncingMoreThanDeflateCanHoldIsTruncated) {
  // 79 bytes of header and gzip announcing 10^15 (and 10^9) voxels: open_nrrd allocated the
  // announced size before inflating (std::bad_alloc, or a gigabyte per file).
  for (const char* name : {"gzip-announces-1e15-bytes.nrrd", "gzip-announces-1e9-bytes.nrrd"}) {
    const std::string path = regression("nrrd_file", name);
    EXPECT_RESOCT_ERROR(open_nrrd(path), ErrorCode::truncated, "announces");
    EXPECT_RESOCT_ERROR(open_nrrd(path), ErrorCode::truncated, path);
  }
}

TEST(FuzzRegressions, NrrdByteSkipPlusSizeWrappingIsOverflow) {
  // byte skip 2^62 + 5 plus 3 * 2^62 data bytes wraps to 5, which a 5-byte gzip stream then
  // satisfied; skipping 2^62 + 5 bytes of it threw std::length_error.
  const std::string path = regression("nrrd_file", "gzip-byte-skip-plus-size-wraps.nrrd");
  EXPECT_RESOCT_ERROR(open_nrrd(path), ErrorCode::overflow, "byte skip plus data size");
}

TEST(FuzzRegressions, TiffPageAnnouncingMorePixelsThanTheFileHoldsIsCorrupt) {
  // 638 bytes whose first page claims 65535x65535 pixels: open_tiff_stack allocated and cleared
  // 4.2 GB before libtiff failed to read the strips.
  const std::string path = regression("tiff_file", "65535x65535-in-638-bytes.tif");
  EXPECT_RESOCT_ERROR(open_tiff_stack(path), ErrorCode::corrupt,
                      "65535x65535 pixels cannot be held");
  EXPECT_RESOCT_ERROR(open_tiff_stack(path), ErrorCode::corrupt, path);
}

TEST(FuzzRegressions, TiffTilesAnnouncingMorePixelsThanTheFileHoldsAreCorrupt) {
  // 283 bytes whose 9x68 page (within the budget) announces 9x1224736773 tiles of u16:
  // open_tiff_stack allocated and cleared a 22 GB tile buffer before libtiff failed to read the
  // tile (libFuzzer stopped it at its 2 GB memory limit; a release build took six minutes).
  const std::string path = regression("tiff_file", "tiles-9x1224736773-in-283-bytes.tif");
  EXPECT_RESOCT_ERROR(open_tiff_stack(path), ErrorCode::corrupt,
                      "9x1224736773 tiles cannot be held");
  EXPECT_RESOCT_ERROR(open_tiff_stack(path), ErrorCode::corrupt, path);
}

TEST(FuzzRegressions, SceneNumberBeyondDoubleRangeIsMalformedJson) {
  // nlohmann::json reports "1e3080" as out_of_range, not parse_error; parse_scene let that
  // escape as a foreign exception.
  EXPECT_RESOCT_ERROR(parse_scene(R"({"camera": {"eye": [1e3080, 0, 0]}})", "s.json"),
                      ErrorCode::corrupt, "s.json: malformed JSON");
  EXPECT_RESOCT_ERROR(
      load_scene(regression("scene_json", "number-literal-1e3080-out-of-range.json")),
      ErrorCode::corrupt, "number overflow");
}
