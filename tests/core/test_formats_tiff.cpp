// TIFF stacks: files written by the test from the TIFF 6.0 layout (its own little writer, so
// the reader is not checked against libtiff by libtiff): both byte orders, 8/16-bit unsigned and
// 32-bit float, strips (uncompressed or Deflate) and tiles, multi-page files and directories of
// single-page files; unsupported layouts and damaged files.

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include <zlib.h>

#include "core/test_brick_store_util.hpp"
#include "resoct/error.hpp"
#include "resoct/formats/pyramid_source.hpp"
#include "resoct/formats/tiff_stack.hpp"
#include "resoct/open_source.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
using test::TempDir;

namespace {

struct Page {
  std::uint32_t width = 7, height = 5;
  std::uint16_t bits = 8, format = 1, spp = 1;  // format 1 = uint, 3 = IEEE float
  bool deflate = false;
  std::uint32_t tile = 0;      // 0: strips of 2 rows; else square tiles (multiple of 16)
  std::vector<double> values;  // width * height, x fastest
};

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
        compress(data.data(), &n, block.data(), uLong(block.size()));
        data.resize(n);
      }
      offsets.push_back(std::uint32_t(bytes_.size()));
      counts.push_back(std::uint32_t(data.size()));
      bytes_.insert(bytes_.end(), data.begin(), data.end());
    };
    auto sample = [&](std::vector<std::uint8_t>& out, std::uint32_t x, std::uint32_t y) {
      const double v = x < p.width && y < p.height ? p.values[y * p.width + x] : 0.0;
      for (std::uint16_t s = 0; s < p.spp; ++s) {
        if (p.bits == 8) out.push_back(std::uint8_t(v));
        if (p.bits == 16) put(out, std::uint16_t(v));
        if (p.bits == 32) put(out, float(v));
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

std::vector<double> values(const Page& p, std::uint32_t z) {
  std::vector<double> v(std::size_t(p.width) * p.height);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double top = p.bits == 8 ? 256.0 : 65536.0;
    v[i] = p.format == 3 ? double(i) * 0.5 - 2.25 + z : std::fmod(double(i * 37 + z * 101), top);
  }
  return v;
}

std::vector<double> level0(const BrickSource& s) {
  const auto& p = dynamic_cast<const PyramidSource&>(s);
  const VolumeDesc& d = s.volume();
  std::vector<std::byte> bytes(d.voxel_count() * voxel_size(d.type));
  p.read_level_box(0, 0, Box3{glm::i64vec3(0), glm::i64vec3(d.extent)}, bytes);
  std::vector<double> v;
  for (std::size_t i = 0; i < d.voxel_count(); ++i) {
    if (d.type == VoxelType::u8) v.push_back(double(std::uint8_t(bytes[i])));
    if (d.type == VoxelType::u16) {
      std::uint16_t x;
      std::memcpy(&x, bytes.data() + 2 * i, 2);
      v.push_back(x);
    }
    if (d.type == VoxelType::f32) {
      float x;
      std::memcpy(&x, bytes.data() + 4 * i, 4);
      v.push_back(x);
    }
  }
  return v;
}

TEST(TiffStack, MultiPageFilesEveryTypeLayoutAndByteOrder) {
  TempDir dir;
  struct Kind {
    std::uint16_t bits, format;
    VoxelType type;
  };
  for (const Kind k :
       {Kind{8, 1, VoxelType::u8}, Kind{16, 1, VoxelType::u16}, Kind{32, 3, VoxelType::f32}}) {
    for (bool big : {false, true}) {
      for (int layout = 0; layout < 3; ++layout) {  // strips, deflate strips, tiles
        SCOPED_TRACE(std::to_string(k.bits) + (big ? " big" : " little") + " layout " +
                     std::to_string(layout));
        Page p;
        p.width = layout == 2 ? 37 : 7;
        p.height = layout == 2 ? 20 : 5;
        p.bits = k.bits;
        p.format = k.format;
        p.deflate = layout == 1;
        p.tile = layout == 2 ? 16 : 0;
        TiffWriter w(big);
        std::vector<double> want;
        for (std::uint32_t z = 0; z < 3; ++z) {
          p.values = values(p, z);
          want.insert(want.end(), p.values.begin(), p.values.end());
          w.page(p);
        }
        test::write_bytes(dir.file("s.tif"), w.bytes());
        const auto src = open_source(dir.file("s.tif"), BrickLayout{glm::uvec3(4), 1});
        EXPECT_EQ(src->volume().type, k.type);
        EXPECT_EQ(src->volume().extent, glm::u64vec3(p.width, p.height, 3));
        EXPECT_EQ(level0(*src), want);
      }
    }
  }
}

TEST(TiffStack, DirectoryOfSinglePageFilesInNameOrder) {
  TempDir dir;
  Page p;
  p.bits = 16;
  std::vector<double> want;
  for (std::uint32_t z = 0; z < 4; ++z) {
    p.values = values(p, z);
    want.insert(want.end(), p.values.begin(), p.values.end());
    TiffWriter w(z % 2 == 1);
    w.page(p);
    test::write_bytes(dir.file("slice_" + std::to_string(z) + (z == 2 ? ".TIFF" : ".tif")),
                      w.bytes());
  }
  test::write_bytes(dir.file("notes.txt"), {'x'});
  EXPECT_EQ(detect_source_kind(dir.path().string()), SourceKind::tiff);
  const auto src = open_source(dir.path().string(), BrickLayout{glm::uvec3(4), 1});
  EXPECT_EQ(src->volume().extent, glm::u64vec3(7, 5, 4));
  EXPECT_EQ(level0(*src), want);
}

TEST(TiffStack, UnsupportedAndDamagedFiles) {
  TempDir dir;
  Page rgb;
  rgb.spp = 3;
  rgb.values = values(rgb, 0);
  TiffWriter w(false);
  w.page(rgb);
  test::write_bytes(dir.file("rgb.tif"), w.bytes());
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.file("rgb.tif")), ErrorCode::unsupported,
                      "page 0: 3 samples per pixel");
  Page a, b;
  a.values = values(a, 0);
  b.width = 8;
  b.values = values(b, 1);
  TiffWriter m(false);
  m.page(a);
  m.page(b);
  test::write_bytes(dir.file("mixed.tif"), m.bytes());
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.file("mixed.tif")), ErrorCode::corrupt, "page 1 is 8x5");
  Page i16;
  i16.bits = 16;
  i16.format = 2;
  i16.values = values(i16, 0);
  TiffWriter s(false);
  s.page(i16);
  test::write_bytes(dir.file("signed.tif"), s.bytes());
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.file("signed.tif")), ErrorCode::unsupported,
                      "16-bit samples of format 2");
  test::write_bytes(dir.file("text.tif"), {'h', 'e', 'l', 'l', 'o'});
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.file("text.tif")), ErrorCode::bad_magic, "text.tif");
  // Damaged Deflate strips (IFD intact): the row is unreadable. Cut short: the IFD at the end
  // is gone, so libtiff does not recognise the file.
  Page big;
  big.width = 64;
  big.height = 64;
  big.deflate = true;
  big.values = values(big, 0);
  TiffWriter t(false);
  t.page(big);
  auto bytes = t.bytes();
  bytes.resize(bytes.size() - 30);
  auto damaged = t.bytes();
  for (std::size_t i = 20; i < 60; ++i) damaged[i] ^= 0x5a;
  test::write_bytes(dir.file("damaged.tif"), damaged);
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.file("damaged.tif")), ErrorCode::corrupt,
                      "damaged.tif: offset 0: page 0: row");
  test::write_bytes(dir.file("cut.tif"), bytes);
  EXPECT_RESOCT_ERROR(open_tiff_stack(dir.file("cut.tif")), ErrorCode::bad_magic, "cut.tif");
  TempDir empty;
  EXPECT_RESOCT_ERROR(open_tiff_stack(empty.path().string()), ErrorCode::invalid_argument,
                      "no .tif/.tiff files");
}

}  // namespace
