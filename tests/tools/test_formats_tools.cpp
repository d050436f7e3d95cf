// The tools on real formats: resoct-convert turns an OME-Zarr image, a NIfTI file, an NRRD file
// and a TIFF stack into brick stores whose bricks equal the directly opened sources, and
// resoct-render renders the Colin27 brain (mricron-data) straight from its .nii.gz.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/io/open_source.hpp"
#include "support/brick_compare.hpp"
#include "support/generated_data.hpp"
#include "support/tiff_writer.hpp"
#include "support/tool_process.hpp"

using resoct::test::shell_quote;
using resoct::test::TempDir;
using resoct::test::ToolRun;

namespace {

// The tools are built next to the tests (the tool tests' own targets depend on them).
const std::string kConvert = RESOCT_BINARY_DIR "/examples/resoct-convert";
const std::string kRender = RESOCT_BINARY_DIR "/examples/resoct-render";
const std::string kTemplates = "/usr/share/mricron/templates/";

void expect_converts_exactly(const TempDir& dir, const std::string& input) {
  SCOPED_TRACE(input);
  const std::string out = dir.file("out.rbs");
  const ToolRun r = resoct::test::run_tool_process(
      dir.path().string(), kConvert,
      shell_quote(input) + " " + shell_quote(out) + " --brick 16 --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Wrote"), std::string::npos);
  const resoct::BrickStoreSource store(out);
  const auto direct = resoct::open_source(input, resoct::BrickLayout{glm::uvec3(16), 1});
  resoct::test::expect_same_bricks(*direct, store);
}

TEST(FormatsTools, ConvertEveryFormatToAStoreWithIdenticalBricks) {
  TempDir dir;
  const std::string zarr = resoct::test::python_generated_dir(
      RESOCT_BINARY_DIR "/test-data", "ome-zarr", RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
  ASSERT_FALSE(zarr.empty());
  expect_converts_exactly(dir, zarr + "/pyramid_f4.zarr");
  expect_converts_exactly(dir, kTemplates + "AICHAmc.nii.gz");
  // NRRD: 20x18x9 u16, gzip, written here.
  std::vector<std::uint8_t> samples;
  for (int i = 0; i < 20 * 18 * 9; ++i) {
    samples.push_back(std::uint8_t(i * 7));
    samples.push_back(std::uint8_t(i / 5));
  }
  const std::string head =
      "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 20 18 9\nencoding: raw\nendian: little\n"
      "spacings: 1 1 2.5\n\n";
  std::vector<std::uint8_t> nrrd(head.begin(), head.end());
  nrrd.insert(nrrd.end(), samples.begin(), samples.end());
  resoct::test::write_bytes(dir.file("v.nrrd"), nrrd);
  expect_converts_exactly(dir, dir.file("v.nrrd"));
  resoct::test::Page p;
  p.width = 33;
  p.height = 21;
  p.bits = 32;
  p.format = 3;
  resoct::test::TiffWriter w(false);
  for (int z = 0; z < 6; ++z) {
    p.values.assign(33 * 21, 0.0);
    for (std::size_t i = 0; i < p.values.size(); ++i) p.values[i] = std::sin(double(i + z * 50));
    w.page(p);
  }
  resoct::test::write_bytes(dir.file("s.tif"), w.bytes());
  expect_converts_exactly(dir, dir.file("s.tif"));
}

TEST(FormatsTools, RendersTheColin27BrainFromNifti) {
  TempDir dir;
  const std::string png = dir.file("brain.png");
  const ToolRun r = resoct::test::run_tool_process(
      dir.path().string(), kRender,
      "--volume " + shell_quote(kTemplates + "ch2better.nii.gz") + " --scene " +
          shell_quote(RESOCT_SOURCE_DIR "/examples/scenes/brain.json") +
          " --width 64 --height 64 --converge --threads 2 --out " + shell_quote(png));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const resoct::Image img = resoct::read_png(png);
  // Foreground: pixels noticeably brighter than the black background.
  std::uint32_t area = 0, x0 = 64, y0 = 64, x1 = 0, y1 = 0;
  for (std::uint32_t y = 0; y < 64; ++y) {
    for (std::uint32_t x = 0; x < 64; ++x) {
      const glm::vec4 c = img.at(x, y);
      if (c.r + c.g + c.b < 0.3f) continue;
      ++area;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  // The side view of the brain covers roughly half of the frame...
  EXPECT_GT(area, 64u * 64u * 30u / 100u);
  EXPECT_LT(area, 64u * 64u * 80u / 100u);
  // ...inside the frame (not cut by it) and around its centre.
  EXPECT_GT(x0, 0u);
  EXPECT_GT(y0, 0u);
  EXPECT_LT(x1, 63u);
  EXPECT_LT(y1, 63u);
  EXPECT_NEAR(double(x0 + x1) / 2.0, 31.5, 10.0);
  EXPECT_NEAR(double(y0 + y1) / 2.0, 31.5, 10.0);
  // A brain is wider (front to back) than tall in a side view.
  EXPECT_GT(x1 - x0, y1 - y0);
}

TEST(FormatsTools, RendersAStackOfT1AndAtlasDirectly) {
  TempDir dir;
  const std::string png = dir.file("stack.png");
  const ToolRun r = resoct::test::run_tool_process(
      dir.path().string(), kRender,
      "--volume " + shell_quote("stack:" + kTemplates + "ch2.nii.gz+" + kTemplates + "aal.nii.gz") +
          " --scene " + shell_quote(RESOCT_SOURCE_DIR "/examples/scenes/brain_atlas.json") +
          " --width 48 --height 48 --converge --threads 2 --out " + shell_quote(png));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const resoct::Image img = resoct::read_png(png);
  // The atlas channel is drawn in saturated colours: some pixels are clearly not gray.
  std::uint32_t coloured = 0;
  for (const glm::vec4& c : img.pixels()) {
    const float mx = std::max({c.r, c.g, c.b}), mn = std::min({c.r, c.g, c.b});
    coloured += mx - mn > 0.2f;
  }
  EXPECT_GT(coloured, 48u * 48u / 20u);
}

}  // namespace
