#pragma once
/// \file
/// RGBA float images, 8-bit conversion, PNG files and image comparison metrics.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

namespace resoct {

/// Straight (not premultiplied) RGBA, nominally in [0, 1], row-major with row 0 at the top.
/// A plain value type; not synchronised.
class Image {
 public:
  Image() = default;
  /// Throws Error(invalid_argument) naming "image size" when a side is 0 or above 65536.
  Image(std::uint32_t width, std::uint32_t height, glm::vec4 fill = glm::vec4(0.0f));

  std::uint32_t width() const noexcept { return width_; }
  std::uint32_t height() const noexcept { return height_; }
  glm::vec4& at(std::uint32_t x, std::uint32_t y) { return pixels_[index(x, y)]; }
  const glm::vec4& at(std::uint32_t x, std::uint32_t y) const { return pixels_[index(x, y)]; }
  std::vector<glm::vec4>& pixels() noexcept { return pixels_; }
  const std::vector<glm::vec4>& pixels() const noexcept { return pixels_; }

  /// 8-bit RGBA, 4 bytes per pixel: round(clamp(v, 0, 1) * 255); NaN becomes 0.
  std::vector<std::uint8_t> to_rgba8() const;
  /// The same into `out` (resized; its capacity is reused, so a viewer converts every frame
  /// without allocating).
  void to_rgba8(std::vector<std::uint8_t>& out) const;
  /// Inverse of to_rgba8 (v / 255). Throws Error(size_mismatch) if the buffer size is wrong.
  static Image from_rgba8(std::uint32_t width, std::uint32_t height,
                          const std::vector<std::uint8_t>& rgba);

  friend bool operator==(const Image&, const Image&) = default;

 private:
  std::size_t index(std::uint32_t x, std::uint32_t y) const { return std::size_t(y) * width_ + x; }
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
  std::vector<glm::vec4> pixels_;
};

/// Writes an 8-bit RGBA PNG atomically: a temporary "<path>.tmp-XXXXXX" in the same directory,
/// fsync, rename. On failure removes the temporary and throws Error(io) naming the path.
void write_png(const Image& image, const std::string& path);
/// The same for 8-bit RGBA pixels (FrameReport::rgba8): `rgba` must hold width * height * 4
/// bytes, else Error(invalid_argument) naming "rgba"; a side outside 1..65536 names "image size".
void write_png(std::uint32_t width, std::uint32_t height, std::span<const std::uint8_t> rgba,
               const std::string& path);
/// Reads any PNG libpng understands, converted to 8-bit RGBA. Error(io) when the file cannot be
/// opened, Error(corrupt) naming the path when it is not a valid PNG.
Image read_png(const std::string& path);

/// Differences between two images of the same size, per channel (r, g, b, a).
struct ImageDiff {
  glm::dvec4 rmse{0.0};     ///< root mean square error per channel
  glm::dvec4 max_abs{0.0};  ///< largest absolute difference per channel
  double rmse_rgb = 0.0;    ///< RMSE over the three colour channels together
  double psnr_rgb = 0.0;    ///< 20 log10(1 / rmse_rgb) in dB (peak 1); +inf when identical
};

/// Throws Error(size_mismatch) when the sizes differ or the images are empty.
ImageDiff compare_images(const Image& a, const Image& b);

}  // namespace resoct
