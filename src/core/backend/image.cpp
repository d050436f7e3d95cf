#include "resoct/backend/image.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <png.h>

#include "resoct/base/file_io.hpp"
#include "resoct/base/error.hpp"

namespace resoct {

Image::Image(std::uint32_t width, std::uint32_t height, glm::vec4 fill)
    : width_(width), height_(height) {
  if (width == 0 || height == 0 || width > 65536 || height > 65536) {
    throw invalid_parameter("image size", "width and height must be in 1..65536");
  }
  pixels_.assign(std::size_t(width) * height, fill);
}

std::vector<std::uint8_t> Image::to_rgba8() const {
  std::vector<std::uint8_t> out;
  to_rgba8(out);
  return out;
}

void Image::to_rgba8(std::vector<std::uint8_t>& out) const {
  out.resize(pixels_.size() * 4);
  for (std::size_t i = 0; i < pixels_.size(); ++i) {
    for (int c = 0; c < 4; ++c) {
      const float v = pixels_[i][c];
      // NaN fails both comparisons and becomes 0.
      const float clamped = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
      out[i * 4 + std::size_t(c)] = std::uint8_t(std::lround(clamped * 255.0f));
    }
  }
}

Image Image::from_rgba8(std::uint32_t width, std::uint32_t height,
                        const std::vector<std::uint8_t>& rgba) {
  Image img(width, height);
  if (rgba.size() != img.pixels_.size() * 4) {
    throw Error(ErrorCode::size_mismatch, "rgba8 buffer of " + std::to_string(rgba.size()) +
                                              " bytes for a " + std::to_string(width) + "x" +
                                              std::to_string(height) + " image");
  }
  for (std::size_t i = 0; i < img.pixels_.size(); ++i) {
    for (int c = 0; c < 4; ++c) img.pixels_[i][c] = float(rgba[i * 4 + std::size_t(c)]) / 255.0f;
  }
  return img;
}

void write_png(const Image& image, const std::string& path) {
  if (image.width() == 0) throw invalid_parameter("image", "is empty");
  write_png(image.width(), image.height(), image.to_rgba8(), path);
}

void write_png(std::uint32_t width, std::uint32_t height, std::span<const std::uint8_t> rgba,
               const std::string& path) {
  if (width == 0 || height == 0 || width > 65536 || height > 65536) {
    throw invalid_parameter("image size", "width and height must be in 1..65536");
  }
  if (rgba.size() != std::size_t(width) * height * 4u) {
    throw invalid_parameter("rgba", std::to_string(rgba.size()) + " bytes for a " +
                                        std::to_string(width) + "x" + std::to_string(height) +
                                        " image (4 bytes per pixel expected)");
  }
  // Encode in memory first: a PNG error then leaves nothing behind, and the file is written
  // through the same atomic writer as every other output.
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = width;
  png.height = height;
  png.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, rgba.data(), 0, nullptr)) {
    const std::string msg = png.message;
    png_image_free(&png);
    throw Error(ErrorCode::io, path + ": PNG encoding failed: " + msg);
  }
  std::vector<std::byte> encoded(size);
  if (!png_image_write_to_memory(&png, encoded.data(), &size, 0, rgba.data(), 0, nullptr)) {
    const std::string msg = png.message;
    png_image_free(&png);
    throw Error(ErrorCode::io, path + ": PNG encoding failed: " + msg);
  }
  png_image_free(&png);
  encoded.resize(size);
  AtomicFileWriter out(path);
  out.append(encoded);
  out.commit();
}

Image read_png(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw Error(ErrorCode::io, path + ": cannot open for reading");
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  auto fail = [&](const char* what) {
    const std::string msg = path + ": " + what + ": " + png.message;
    png_image_free(&png);
    std::fclose(f);
    return Error(ErrorCode::corrupt, msg);
  };
  std::uint64_t file_bytes = 0;
  if (std::fseek(f, 0, SEEK_END) == 0) {
    const long end = std::ftell(f);
    file_bytes = end > 0 ? std::uint64_t(end) : 0;
  }
  std::rewind(f);
  if (!png_image_begin_read_from_stdio(&png, f)) throw fail("not a readable PNG");
  if (png.width == 0 || png.height == 0 || png.width > 65536 || png.height > 65536) {
    throw fail("image size outside 1..65536");
  }
  // The pixels are deflated rows of at least one bit per pixel plus a filter byte, and deflate
  // expands at most 1032:1. A header announcing more than the file can hold is corrupt; without
  // this check an 83-byte file made us allocate and clear gigabytes before libpng noticed.
  const std::uint64_t min_raw =
      std::uint64_t(png.height) * (1 + (std::uint64_t(png.width) + 7) / 8);
  if (min_raw / 1032 > file_bytes) {
    const std::string msg = path + ": a " + std::to_string(png.width) + "x" +
                            std::to_string(png.height) + " image cannot be stored in " +
                            std::to_string(file_bytes) + " bytes";
    png_image_free(&png);
    std::fclose(f);
    throw Error(ErrorCode::corrupt, msg);
  }
  png.format = PNG_FORMAT_RGBA;
  std::vector<std::uint8_t> rgba(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, rgba.data(), 0, nullptr)) {
    throw fail("decoding failed");
  }
  const std::uint32_t w = png.width;
  const std::uint32_t h = png.height;
  png_image_free(&png);
  std::fclose(f);
  return Image::from_rgba8(w, h, rgba);
}

ImageDiff compare_images(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.pixels().empty()) {
    throw Error(ErrorCode::size_mismatch,
                "compare_images: " + std::to_string(a.width()) + "x" + std::to_string(a.height()) +
                    " vs " + std::to_string(b.width()) + "x" + std::to_string(b.height()));
  }
  glm::dvec4 sum_sq(0.0);
  ImageDiff d;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const glm::dvec4 diff = glm::dvec4(a.pixels()[i]) - glm::dvec4(b.pixels()[i]);
    for (int c = 0; c < 4; ++c) {
      sum_sq[c] += diff[c] * diff[c];
      d.max_abs[c] = std::max(d.max_abs[c], std::abs(diff[c]));
    }
  }
  const double n = double(a.pixels().size());
  for (int c = 0; c < 4; ++c) d.rmse[c] = std::sqrt(sum_sq[c] / n);
  d.rmse_rgb = std::sqrt((sum_sq.r + sum_sq.g + sum_sq.b) / (3.0 * n));
  d.psnr_rgb =
      d.rmse_rgb > 0.0 ? -20.0 * std::log10(d.rmse_rgb) : std::numeric_limits<double>::infinity();
  return d;
}

}  // namespace resoct
