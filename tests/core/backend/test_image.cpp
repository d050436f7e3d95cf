// Images: 8-bit conversion, atomic PNG write and read back, comparison metrics.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "resoct/backend/image.hpp"
#include "support/expect_error.hpp"

namespace {

using namespace resoct;
namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("resoct_test_image_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(Image, Rgba8Conversion) {
  Image img(2, 1);
  img.at(0, 0) = glm::vec4(0.0f, 0.5f, 1.0f, 2.0f);
  img.at(1, 0) = glm::vec4(-1.0f, std::nanf(""), 0.2f, 1.0f);
  const std::vector<std::uint8_t> b = img.to_rgba8();
  const std::vector<std::uint8_t> expect = {0, 128, 255, 255, 0, 0, 51, 255};
  EXPECT_EQ(b, expect);
  EXPECT_RESOCT_ERROR(Image::from_rgba8(2, 2, b), ErrorCode::size_mismatch, "rgba8");
  EXPECT_RESOCT_ERROR(Image(0, 3), ErrorCode::invalid_argument, "image size");
}

TEST(Image, PngRoundTrip) {
  const fs::path dir = temp_dir("roundtrip");
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> byte(0, 255);
  Image img(37, 19);
  for (glm::vec4& p : img.pixels()) {
    p = glm::vec4(byte(rng), byte(rng), byte(rng), byte(rng)) / 255.0f;
  }
  const std::string path = (dir / "a.png").string();
  write_png(img, path);
  const Image back = read_png(path);
  ASSERT_EQ(back.width(), 37u);
  ASSERT_EQ(back.height(), 19u);
  EXPECT_EQ(back.to_rgba8(), img.to_rgba8());
  // Only the PNG is left: no temporaries.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1);
  // Overwriting replaces the file.
  Image black(3, 2, glm::vec4(0, 0, 0, 1));
  write_png(black, path);
  EXPECT_EQ(read_png(path).width(), 3u);
  fs::remove_all(dir);
}

TEST(Image, WriteIntoMissingDirectoryThrowsAndLeavesNothing) {
  const fs::path dir = temp_dir("missing");
  const fs::path path = dir / "no_such_dir" / "x.png";
  EXPECT_RESOCT_ERROR(write_png(Image(2, 2), path.string()), ErrorCode::io, path.string());
  EXPECT_FALSE(fs::exists(dir / "no_such_dir"));
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(Image, ReadErrors) {
  const fs::path dir = temp_dir("read");
  EXPECT_RESOCT_ERROR(read_png((dir / "none.png").string()), ErrorCode::io, "none.png");
  const fs::path bad = dir / "bad.png";
  std::ofstream(bad) << "not a png at all";
  EXPECT_RESOCT_ERROR(read_png(bad.string()), ErrorCode::corrupt, "bad.png");
  fs::remove_all(dir);
}

TEST(Image, MetricsOfKnownImages) {
  Image a(4, 4, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  Image b = a;
  const ImageDiff same = compare_images(a, b);
  EXPECT_EQ(same.rmse_rgb, 0.0);
  EXPECT_TRUE(std::isinf(same.psnr_rgb));
  // One pixel's red off by 0.4 out of 16 pixels: red RMSE = sqrt(0.16 / 16) = 0.1,
  // RGB RMSE = sqrt(0.16 / 48), PSNR = -20 log10 of that.
  b.at(1, 2).r = 0.9f;
  const ImageDiff d = compare_images(a, b);
  EXPECT_NEAR(d.rmse.r, 0.1, 1e-7);
  EXPECT_EQ(d.rmse.g, 0.0);
  EXPECT_NEAR(d.max_abs.r, 0.4, 1e-7);
  EXPECT_EQ(d.max_abs.a, 0.0);
  const double rgb = std::sqrt(0.16 / 48.0);
  EXPECT_NEAR(d.rmse_rgb, rgb, 1e-7);
  EXPECT_NEAR(d.psnr_rgb, -20.0 * std::log10(rgb), 1e-5);
  // Uniform offset 0.1 on all colour channels: PSNR 20 dB.
  Image c(4, 4, glm::vec4(0.6f, 0.6f, 0.6f, 1.0f));
  EXPECT_NEAR(compare_images(a, c).psnr_rgb, 20.0, 1e-4);
  EXPECT_RESOCT_ERROR(compare_images(a, Image(3, 4)), ErrorCode::size_mismatch, "4x4 vs 3x4");
}

}  // namespace
