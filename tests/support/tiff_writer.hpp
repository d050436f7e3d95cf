#pragma once
// A minimal TIFF 6.0 writer for tests, written from the specification (not libtiff), so that
// the reader is checked against an independent encoder: grayscale pages in either byte order,
// strips of two rows (uncompressed or Deflate) or square tiles, multi-page files.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include <zlib.h>

namespace resoct::test {

/// One page: its layout and width * height sample values (x fastest).
struct Page {
  std::uint32_t width = 7, height = 5;
  std::uint16_t bits = 8, format = 1, spp = 1;  // format 1 = uint, 2 = int, 3 = IEEE float
  bool deflate = false;
  std::uint32_t tile = 0;      // 0: strips of 2 rows; else square tiles (multiple of 16)
  std::vector<double> values;  // width * height, x fastest
};

/// Appends pages to an in-memory TIFF file; bytes() is the whole file.
class TiffWriter {
 public:
  explicit TiffWriter(bool big) : big_(big) {
    bytes_ = {std::uint8_t(big ? 'M' : 'I'), std::uint8_t(big ? 'M' : 'I')};
    u16(42);
    next_ifd_at_ = bytes_.size();
    u32(0);
  }

  void page(const Page& p) {
    std::vector<std::uint32_t> offsets, counts;
    auto emit = [&](const std::vector<std::uint8_t>& block) {
      std::vector<std::uint8_t> data = block;
      if (p.deflate) {
        uLongf n = compressBound(uLong(block.size()));
        data.resize(n);
        ::compress(data.data(), &n, block.data(), uLong(block.size()));
        data.resize(n);
      }
      offsets.push_back(std::uint32_t(bytes_.size()));
      counts.push_back(std::uint32_t(data.size()));
      bytes_.insert(bytes_.end(), data.begin(), data.end());
    };
    auto sample = [&](std::vector<std::uint8_t>& out, std::uint32_t x, std::uint32_t y) {
      const double v = x < p.width && y < p.height ? p.values[y * p.width + x] : 0.0;
      for (std::uint16_t s = 0; s < p.spp; ++s) {
        const bool sint = p.format == 2, real = p.format == 3;
        if (p.bits == 8) out.push_back(sint ? std::uint8_t(std::int8_t(v)) : std::uint8_t(v));
        if (p.bits == 16 && !sint) put(out, std::uint16_t(v));
        if (p.bits == 16 && sint) put(out, std::int16_t(v));
        if (p.bits == 32 && real) put(out, float(v));
        if (p.bits == 32 && !real && !sint) put(out, std::uint32_t(v));
        if (p.bits == 32 && sint) put(out, std::int32_t(v));
        if (p.bits == 64 && real) put(out, v);
      }
    };
    const std::uint32_t rows = 2;
    if (p.tile == 0) {
      for (std::uint32_t y0 = 0; y0 < p.height; y0 += rows) {
        std::vector<std::uint8_t> block;
        for (std::uint32_t y = y0; y < std::min(p.height, y0 + rows); ++y)
          for (std::uint32_t x = 0; x < p.width; ++x) sample(block, x, y);
        emit(block);
      }
    } else {
      for (std::uint32_t y0 = 0; y0 < p.height; y0 += p.tile)
        for (std::uint32_t x0 = 0; x0 < p.width; x0 += p.tile) {
          std::vector<std::uint8_t> block;
          for (std::uint32_t y = y0; y < y0 + p.tile; ++y)
            for (std::uint32_t x = x0; x < x0 + p.tile; ++x) sample(block, x, y);
          emit(block);
        }
    }
    const std::uint32_t offsets_at = array(offsets), counts_at = array(counts);
    struct Entry {
      std::uint16_t tag, type;
      std::uint32_t count, value;
    };
    std::vector<Entry> e = {{256, 4, 1, p.width}, {257, 4, 1, p.height},
                            {258, 3, 1, p.bits},  {259, 3, 1, p.deflate ? 8u : 1u},
                            {262, 3, 1, 1},       {277, 3, 1, p.spp}};
    auto ref = [&](std::uint32_t at, const std::vector<std::uint32_t>& v) {
      return v.size() == 1 ? v[0] : at;
    };
    if (p.tile == 0) {
      e.push_back({273, 4, std::uint32_t(offsets.size()), ref(offsets_at, offsets)});
      e.push_back({278, 4, 1, rows});
      e.push_back({279, 4, std::uint32_t(counts.size()), ref(counts_at, counts)});
    }
    if (p.tile != 0) {
      e.push_back({322, 4, 1, p.tile});
      e.push_back({323, 4, 1, p.tile});
      e.push_back({324, 4, std::uint32_t(offsets.size()), ref(offsets_at, offsets)});
      e.push_back({325, 4, std::uint32_t(counts.size()), ref(counts_at, counts)});
    }
    e.push_back({339, 3, 1, p.format});
    align();
    patch32(next_ifd_at_, std::uint32_t(bytes_.size()));
    u16(std::uint16_t(e.size()));
    for (const Entry& x : e) {
      u16(x.tag);
      u16(x.type);
      u32(x.count);
      if (x.type == 3) {
        u16(std::uint16_t(x.value));
        u16(0);
      } else {
        u32(x.value);
      }
    }
    next_ifd_at_ = bytes_.size();
    u32(0);
  }

  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  template <typename T>
  void put(std::vector<std::uint8_t>& out, T v) {
    std::uint8_t tmp[sizeof(T)];
    std::memcpy(tmp, &v, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T); ++i)
      out.push_back(big_ ? tmp[sizeof(T) - 1 - i] : tmp[i]);
  }
  void u16(std::uint16_t v) { put(bytes_, v); }
  void u32(std::uint32_t v) { put(bytes_, v); }
  void align() {
    if (bytes_.size() % 2) bytes_.push_back(0);
  }
  std::uint32_t array(const std::vector<std::uint32_t>& v) {
    align();
    const auto at = std::uint32_t(bytes_.size());
    for (std::uint32_t x : v) u32(x);
    return at;
  }
  void patch32(std::size_t at, std::uint32_t v) {
    std::vector<std::uint8_t> tmp;
    put(tmp, v);
    std::memcpy(bytes_.data() + at, tmp.data(), 4);
  }
  bool big_;
  std::vector<std::uint8_t> bytes_;
  std::size_t next_ifd_at_ = 0;
};

}  // namespace resoct::test
