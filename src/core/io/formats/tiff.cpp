#include <algorithm>
#include <bit>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <tiffio.h>

#include "io/storage/confined_path.hpp"
#include "io/formats/samples.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/pyramid_source.hpp"
#include "resoct/io/formats/tiff_stack.hpp"

namespace resoct {

namespace {

/// libtiff reports through handlers; this one keeps the last message per open file so that it
/// ends up in the Error instead of on stderr.
int capture(TIFF*, void* user, const char* module, const char* fmt, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, fmt, ap);
  auto* out = static_cast<std::string*>(user);
  *out = std::string(module != nullptr ? module : "libtiff") + ": " + text;
  return 1;
}

int ignore(TIFF*, void*, const char*, const char*, va_list) {
  return 1;
}

class TiffFile {
 public:
  explicit TiffFile(const std::string& path) : path_(path) {
    std::error_code ec;
    bytes_ = std::filesystem::file_size(path, ec);
    TIFFOpenOptions* o = TIFFOpenOptionsAlloc();
    TIFFOpenOptionsSetErrorHandlerExtR(o, capture, &message_);
    TIFFOpenOptionsSetWarningHandlerExtR(o, ignore, nullptr);
    tif_ = TIFFOpenExt(path.c_str(), "r", o);
    TIFFOpenOptionsFree(o);
    if (tif_ == nullptr) {
      throw file_error(
          ErrorCode::bad_magic, path, 0,
          "not a readable TIFF file" + (message_.empty() ? "" : " (" + message_ + ")"));
    }
  }
  TiffFile(const TiffFile&) = delete;
  TiffFile& operator=(const TiffFile&) = delete;
  ~TiffFile() { TIFFClose(tif_); }
  TIFF* get() const noexcept { return tif_; }
  const std::string& path() const noexcept { return path_; }
  std::string message() const { return message_.empty() ? "" : " (" + message_ + ")"; }
  /// Most pixel bytes a page of this file can decode to: no TIFF codec expands beyond 4096:1
  /// (LZW's longest string per 12-bit code), so larger claims are corrupt, and are rejected
  /// before anything is allocated for them.
  std::uint64_t max_page_bytes() const noexcept { return bytes_ * 4096 + (1u << 20); }

 private:
  std::string path_;
  std::string message_;
  std::uint64_t bytes_ = 0;
  TIFF* tif_ = nullptr;
};

struct PageFormat {
  std::uint32_t width = 0, height = 0;
  std::uint16_t bits = 0, format = SAMPLEFORMAT_UINT;
  friend bool operator==(const PageFormat&, const PageFormat&) = default;
};

/// The value type of a page's samples, or nothing when resoct does not read it.
std::optional<DataType> data_type(const PageFormat& p) {
  if (p.format == SAMPLEFORMAT_UINT) {
    if (p.bits == 8) return DataType::u8;
    if (p.bits == 16) return DataType::u16;
    if (p.bits == 32) return DataType::u32;
  } else if (p.format == SAMPLEFORMAT_INT) {
    if (p.bits == 8) return DataType::i8;
    if (p.bits == 16) return DataType::i16;
    if (p.bits == 32) return DataType::i32;
  } else if (p.format == SAMPLEFORMAT_IEEEFP) {
    if (p.bits == 32) return DataType::f32;
    if (p.bits == 64) return DataType::f64;
  }
  return std::nullopt;
}

PageFormat page_format(const TiffFile& f, std::uint64_t page) {
  TIFF* t = f.get();
  PageFormat p;
  std::uint16_t spp = 1;
  TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &p.width);
  TIFFGetField(t, TIFFTAG_IMAGELENGTH, &p.height);
  TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &p.bits);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &p.format);
  const std::string where = "page " + std::to_string(page) + ": ";
  if (p.width == 0 || p.height == 0) {
    throw file_error(ErrorCode::corrupt, f.path(), 0, where + "zero width or height");
  }
  if (spp != 1) {
    throw file_error(ErrorCode::unsupported, f.path(), 0,
                     where + std::to_string(spp) + " samples per pixel (grayscale only)");
  }
  if (!data_type(p)) {
    throw file_error(ErrorCode::unsupported, f.path(), 0,
                     where + std::to_string(p.bits) + "-bit samples of format " +
                         std::to_string(p.format) +
                         " (8/16/32-bit signed or unsigned integers, 32/64-bit float only)");
  }
  return p;
}

/// Appends the current page's pixels (rows top to bottom, x fastest) to `out`. `budget` is what
/// the rest of the file can still decode to (TiffFile::max_page_bytes() for all its pages
/// together, so many small IFDs cannot multiply it); the page is charged against it before
/// anything is allocated.
void read_page(const TiffFile& f, const PageFormat& p, std::uint64_t page,
               std::vector<std::byte>& out, std::uint64_t& budget) {
  TIFF* t = f.get();
  const std::size_t vs = p.bits / 8u;
  const std::size_t row = std::size_t(p.width) * vs;
  const std::size_t base = out.size();
  auto fail = [&](const std::string& what) {
    return file_error(ErrorCode::corrupt, f.path(), 0,
                      "page " + std::to_string(page) + ": " + what + f.message());
  };
  // Checked before allocating: a 200-byte header announcing 65535x65535 pixels made this
  // allocate 4 GB, and width * height * 4 bytes can wrap 64 bits.
  std::uint64_t bytes = 0;
  if (__builtin_mul_overflow(std::uint64_t(row), std::uint64_t(p.height), &bytes) ||
      bytes > budget) {
    throw fail(std::to_string(p.width) + "x" + std::to_string(p.height) +
               " pixels cannot be held by a file of this size");
  }
  const std::uint64_t page_budget = budget;
  budget -= bytes;
  if (TIFFIsTiled(t) != 0) {
    std::uint32_t tw = 0, th = 0;
    TIFFGetField(t, TIFFTAG_TILEWIDTH, &tw);
    TIFFGetField(t, TIFFTAG_TILELENGTH, &th);
    if (tw == 0 || th == 0) throw fail("zero tile size");
    // The tile buffer is decoded pixels too, checked like the page's before allocating: a
    // 283-byte file with a 9x68 page announcing 9x1224736773 tiles made this allocate 22 GB.
    const std::uint64_t tile_bytes = TIFFTileSize64(t);
    if (tile_bytes > page_budget) {
      throw fail(std::to_string(tw) + "x" + std::to_string(th) +
                 " tiles cannot be held by a file of this size");
    }
    out.resize(base + std::size_t(bytes));
    std::vector<std::byte> tile(static_cast<std::size_t>(tile_bytes));
    if (tile.size() < std::size_t(tw) * th * vs) throw fail("tile buffer smaller than a tile");
    for (std::uint32_t y0 = 0; y0 < p.height; y0 += th) {
      for (std::uint32_t x0 = 0; x0 < p.width; x0 += tw) {
        if (TIFFReadTile(t, tile.data(), x0, y0, 0, 0) < 0) {
          throw fail("tile at " + std::to_string(x0) + "," + std::to_string(y0) + " unreadable");
        }
        const std::uint32_t w = std::min(tw, p.width - x0), h = std::min(th, p.height - y0);
        for (std::uint32_t y = 0; y < h; ++y) {
          std::memcpy(out.data() + base + (y0 + y) * row + x0 * vs, tile.data() + y * tw * vs,
                      w * vs);
        }
      }
    }
    return;
  }
  if (std::size_t(TIFFScanlineSize(t)) != row) throw fail("unexpected scanline size");
  out.resize(base + std::size_t(bytes));
  for (std::uint32_t y = 0; y < p.height; ++y) {
    if (TIFFReadScanline(t, out.data() + base + y * row, y, 0) < 0) {
      throw fail("row " + std::to_string(y) + " unreadable");
    }
  }
}

std::vector<std::string> stack_files(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return {path};
  // The directory is what the user named; its entries are not: a symbolic link among the
  // slices must not make the stack read a file from elsewhere.
  const fs::path root = detail::canonical_root(path);
  std::vector<std::pair<std::string, std::string>> entries;  // (entry, resolved), sorted by entry
  for (const auto& e : fs::directory_iterator(path, ec)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](char c) { return char(std::tolower(c)); });
    if (e.is_regular_file() && (ext == ".tif" || ext == ".tiff")) {
      entries.emplace_back(e.path().string(),
                           detail::check_confined(root, e.path(), path).string());
    }
  }
  if (ec) throw file_error(ErrorCode::io, path, 0, "cannot list directory: " + ec.message());
  if (entries.empty()) throw invalid_parameter("path", "'" + path + "' holds no .tif/.tiff files");
  std::sort(entries.begin(), entries.end());
  std::vector<std::string> files;
  for (auto& [entry, resolved] : entries) files.push_back(std::move(resolved));
  return files;
}

}  // namespace

std::unique_ptr<BrickSource> open_tiff_stack(const std::string& path, const BrickLayout& layout) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw file_error(ErrorCode::io, path, 0, "does not exist");
  }
  std::vector<std::byte> voxels;
  PageFormat first;
  std::uint64_t pages = 0;
  for (const std::string& file : stack_files(path)) {
    const TiffFile f(file);
    std::uint64_t budget = f.max_page_bytes();
    std::uint64_t page_in_file = 0;
    do {
      const PageFormat p = page_format(f, page_in_file);
      if (pages == 0) {
        first = p;
      } else if (!(p == first)) {
        throw file_error(ErrorCode::corrupt, file, 0,
                         "page " + std::to_string(page_in_file) + " is " + std::to_string(p.width) +
                             "x" + std::to_string(p.height) + " " + std::to_string(p.bits) +
                             "-bit, the first page " + std::to_string(first.width) + "x" +
                             std::to_string(first.height) + " " + std::to_string(first.bits) +
                             "-bit");
      }
      read_page(f, p, page_in_file, voxels, budget);
      ++pages;
      ++page_in_file;
    } while (TIFFReadDirectory(f.get()) == 1);
  }
  VolumeDesc d;
  d.extent = {first.width, first.height, pages};
  const DataType type = *data_type(first);
  d.type = detail::voxel_type_for(type, false);
  if (data_type_of(d.type) != type) {
    // libtiff hands out samples in host byte order.
    const Endian host = std::endian::native == std::endian::little ? Endian::little : Endian::big;
    std::vector<std::byte> kept(voxels.size() / data_size(type) * voxel_size(d.type));
    detail::convert_samples(voxels, type, host, false, 1.0, 0.0, kept);
    voxels = std::move(kept);
    d.data_type = type;
  }
  PyramidSourceOptions o;
  o.ranges_from_data = true;
  // The voxels are read (or mapped) whole at open anyway, so the scan adds at most as much
  // again, and data-derived ranges beat a type's default range for float data.
  o.eager_scan_voxels = std::numeric_limits<std::uint64_t>::max();
  return make_dense_pyramid_source(DenseVolume::from_bytes(d, std::move(voxels)), layout, path, o);
}

}  // namespace resoct
