// Seeds of the format targets: zarr metadata and chunks, OME-NGFF attributes, whole OME-Zarr
// stores, NIfTI and NRRD headers and files, TIFF stacks and PNG images. Part of
// resoct_fuzz_seeds (make_seeds.cpp).

#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <blosc.h>
#include <glm/vec2.hpp>
#include <tiffio.h>
#include <zlib.h>

#include "make_seeds.hpp"
#include "resoct/io/storage/codec.hpp"
#include "resoct/backend/image.hpp"

namespace resoct::fuzz::seeds {

namespace {

void zarr_meta_seeds(std::vector<Seed>& out) {
  const char* metas[] = {
      R"({"zarr_format": 2, "shape": [40, 33, 17], "chunks": [16, 16, 16], "dtype": "|u1",
 "order": "C", "compressor": {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1,
 "blocksize": 0}, "fill_value": 0, "filters": null})",
      R"({"zarr_format": 2, "shape": [64, 64], "chunks": [32, 64], "dtype": "<u2", "order": "C",
 "compressor": {"id": "zstd", "level": 3}, "fill_value": 7, "filters": [],
 "dimension_separator": "/"})",
      R"({"zarr_format": 2, "shape": [1, 2, 10, 20, 30], "chunks": [1, 1, 10, 10, 10],
 "dtype": ">f4", "order": "C", "compressor": null, "fill_value": "NaN", "filters": null})",
      R"({"zarr_format": 2, "shape": [5, 6, 7], "chunks": [5, 6, 7], "dtype": "<f4",
 "order": "C", "compressor": {"id": "gzip", "level": 1}, "fill_value": -1.5})",
      R"({"zarr_format": 2, "shape": [9], "chunks": [4], "dtype": ">u2", "order": "C",
 "compressor": {"id": "zlib", "level": 6}, "fill_value": null, "dimension_separator": "."})",
      R"({"zarr_format": 2, "shape": [3, 300, 300], "chunks": [1, 128, 128], "dtype": "<u1",
 "order": "C", "compressor": {"id": "lz4", "acceleration": 1}, "fill_value": 255})",
  };
  int i = 0;
  for (const char* m : metas) {
    out.push_back({"zarr_meta", "seed-" + std::to_string(i++) + ".zarray", text_bytes(m)});
  }
}

void ome_seeds(std::vector<Seed>& out) {
  const char* attrs[] = {
      R"({"multiscales": [{"version": "0.4", "name": "cells",
  "axes": [{"name": "c", "type": "channel"},
           {"name": "z", "type": "space", "unit": "micrometer"},
           {"name": "y", "type": "space", "unit": "micrometer"},
           {"name": "x", "type": "space", "unit": "micrometer"}],
  "datasets": [
    {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 0.5, 0.25, 0.25]}]},
    {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 0.5, 0.5]},
      {"type": "translation", "translation": [0, 0.25, 0.125, 0.125]}]}],
  "coordinateTransformations": [{"type": "scale", "scale": [1, 2, 1, 1]}]}],
 "omero": {"channels": [
   {"label": "DAPI", "color": "0000FF", "window": {"start": 0, "end": 1500, "min": 0, "max": 65535}},
   {"label": "GFP", "color": "00FF00", "window": {"start": 100, "end": 4000}}]}})",
      R"({"multiscales": [{"version": "0.4",
  "axes": [{"name": "t", "type": "time", "unit": "second"}, {"name": "c", "type": "channel"},
           {"name": "z", "type": "space"}, {"name": "y", "type": "space"},
           {"name": "x", "type": "space"}],
  "datasets": [{"path": "s0", "coordinateTransformations": [
      {"type": "scale", "scale": [1, 1, 2, 0.5, 0.5]}]}]}]})",
      R"({"multiscales": [{"version": "0.4", "name": "yx",
  "axes": [{"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
  "datasets": [{"path": "a/0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1]}]},
               {"path": "a/1", "coordinateTransformations": [{"type": "scale", "scale": [2, 2]}]},
               {"path": "a/2", "coordinateTransformations": [{"type": "scale", "scale": [4, 4]}]}]}]})",
  };
  int i = 0;
  for (const char* a : attrs) {
    out.push_back({"ome_multiscales", "seed-" + std::to_string(i++) + ".zattrs", text_bytes(a)});
  }
}

// A NIfTI-1 header (348 bytes) plus the 4-byte extension flag, in either byte order.
struct NiftiFields {
  bool big = false;
  std::int16_t dim[8] = {3, 8, 8, 4, 1, 1, 1, 1};
  std::int16_t datatype = 2, bitpix = 8;
  float pixdim[8] = {1, 1, 1, 2.5f, 1, 1, 1, 1};
  float vox_offset = 352, slope = 0, inter = 0;
  std::int16_t qform = 0, sform = 0;
  float srow[12] = {};
};

std::vector<std::byte> nifti(const NiftiFields& f) {
  std::vector<std::byte> b(352, std::byte{0});
  auto put = [&](std::size_t at, const void* v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      b[at + (f.big ? n - 1 - i : i)] = static_cast<const std::byte*>(v)[i];
    }
  };
  const std::int32_t sizeof_hdr = 348;
  put(0, &sizeof_hdr, 4);
  for (std::size_t i = 0; i < 8; ++i) put(40 + 2 * i, &f.dim[i], 2);
  put(70, &f.datatype, 2);
  put(72, &f.bitpix, 2);
  for (std::size_t i = 0; i < 8; ++i) put(76 + 4 * i, &f.pixdim[i], 4);
  put(108, &f.vox_offset, 4);
  put(112, &f.slope, 4);
  put(116, &f.inter, 4);
  put(252, &f.qform, 2);
  put(254, &f.sform, 2);
  for (std::size_t i = 0; i < 12; ++i) put(280 + 4 * i, &f.srow[i], 4);
  std::memcpy(b.data() + 344, "n+1", 4);
  return b;
}

void nifti_seeds(std::vector<Seed>& out) {
  NiftiFields a;
  out.push_back({"nifti_header", "seed-u8-le.nii", nifti(a)});
  NiftiFields b;
  b.big = true;
  b.dim[0] = 4;
  b.dim[4] = 3;
  b.datatype = 4;
  b.bitpix = 16;
  b.sform = 1;
  const float srow[12] = {0, -0.5f, 0, 10, 0.5f, 0, 0, -5, 0, 0, 2, 0};
  std::memcpy(b.srow, srow, sizeof srow);
  out.push_back({"nifti_header", "seed-i16-be-4d-sform.nii", nifti(b)});
  NiftiFields c;
  c.datatype = 16;
  c.bitpix = 32;
  c.slope = 0.5f;
  c.inter = -10;
  c.qform = 1;
  c.vox_offset = 400;
  out.push_back({"nifti_header", "seed-f32-scaled.nii", nifti(c)});
  NiftiFields d;
  d.dim[0] = 2;
  d.dim[1] = 30;
  d.dim[2] = 20;
  d.datatype = 512;
  d.bitpix = 16;
  out.push_back({"nifti_header", "seed-u16-2d.nii", nifti(d)});
}

// A NIfTI-2 header (540 bytes) plus the 4-byte extension flag, in either byte order.
struct Nifti2Fields {
  bool big = false;
  const char* magic = "n+2\0\r\n\032\n";
  std::int64_t dim[8] = {3, 8, 8, 4, 1, 1, 1, 1};
  std::int16_t datatype = 2, bitpix = 8;
  double pixdim[8] = {1, 1, 1, 2.5, 1, 1, 1, 1};
  std::int64_t vox_offset = 544;
  double slope = 0, inter = 0;
  std::int32_t qform = 0, sform = 0;
  double quatern[3] = {}, qoffset[3] = {};
  double srow[12] = {};
};

std::vector<std::byte> nifti2(const Nifti2Fields& f) {
  std::vector<std::byte> b(544, std::byte{0});
  auto put = [&](std::size_t at, const void* v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      b[at + (f.big ? n - 1 - i : i)] = static_cast<const std::byte*>(v)[i];
    }
  };
  const std::int32_t sizeof_hdr = 540;
  put(0, &sizeof_hdr, 4);
  std::memcpy(b.data() + 4, f.magic, 8);
  put(12, &f.datatype, 2);
  put(14, &f.bitpix, 2);
  for (std::size_t i = 0; i < 8; ++i) put(16 + 8 * i, &f.dim[i], 8);
  for (std::size_t i = 0; i < 8; ++i) put(104 + 8 * i, &f.pixdim[i], 8);
  put(168, &f.vox_offset, 8);
  put(176, &f.slope, 8);
  put(184, &f.inter, 8);
  put(344, &f.qform, 4);
  put(348, &f.sform, 4);
  for (std::size_t i = 0; i < 3; ++i) put(352 + 8 * i, &f.quatern[i], 8);
  for (std::size_t i = 0; i < 3; ++i) put(376 + 8 * i, &f.qoffset[i], 8);
  for (std::size_t i = 0; i < 12; ++i) put(400 + 8 * i, &f.srow[i], 8);
  return b;
}

void nifti2_seeds(std::vector<Seed>& out) {
  Nifti2Fields a;
  out.push_back({"nifti_header", "seed-nifti2-u8-le.nii", nifti2(a)});
  Nifti2Fields b;
  b.big = true;
  b.dim[0] = 5;
  b.dim[4] = 3;
  b.dim[5] = 2;
  b.datatype = 4;
  b.bitpix = 16;
  b.sform = 1;
  const double srow[12] = {0, -0.5, 0, 10, 0.5, 0, 0, -5, 0, 0, 2, 0};
  std::memcpy(b.srow, srow, sizeof srow);
  out.push_back({"nifti_header", "seed-nifti2-i16-be-5d-sform.nii", nifti2(b)});
  Nifti2Fields c;
  c.magic = "ni2\0\r\n\032\n";
  c.datatype = 64;
  c.bitpix = 64;
  c.vox_offset = 0;
  c.qform = 1;
  c.pixdim[0] = -1;
  c.quatern[2] = 1;
  c.qoffset[0] = 4;
  out.push_back({"nifti_header", "seed-nifti2-pair-f64-qform.hdr", nifti2(c)});
  NiftiFields d;  // Analyze 7.5: no magic, data at offset 0 of the .img
  d.vox_offset = 0;
  auto analyze = nifti(d);
  std::memset(analyze.data() + 344, 0, 4);
  analyze.resize(348);
  out.push_back({"nifti_header", "seed-analyze-u8.hdr", analyze});
}

void nrrd_seeds(std::vector<Seed>& out) {
  const char* headers[] = {
      "NRRD0004\n# a comment\ntype: uint8\ndimension: 3\nsizes: 8 8 4\nencoding: raw\n"
      "spacings: 1 1 2.5\n\n",
      "NRRD0005\ntype: float\ndimension: 4\nsizes: 3 16 16 8\n"
      "kinds: vector domain domain domain\nendian: big\nencoding: gzip\n"
      "space: right-anterior-superior\n"
      "space directions: none (0.5,0,0) (0,0.5,0) (0,0,1.5)\nspace origin: (0,0,0)\n\n",
      "NRRD0004\ntype: ushort\ndimension: 4\nsizes: 10 10 10 2\n"
      "kinds: domain domain domain list\nendian: little\nencoding: raw\ndata file: vol.raw\n"
      "byte skip: -1\n",
      "NRRD0001\ntype: short\ndimension: 2\nsizes: 32 32\nencoding: gz\nline skip: 2\n"
      "byte skip: 4\nspacings: 0.5 nan\nkey:=value\n\n\x01\x02",
  };
  int i = 0;
  for (const char* h : headers) {
    out.push_back({"nrrd_header", "seed-" + std::to_string(i++) + ".nhdr", text_bytes(h)});
  }
}

std::vector<std::byte> deflate(const std::vector<std::byte>& in, bool gzip) {
  z_stream z{};
  deflateInit2(&z, 6, Z_DEFLATED, gzip ? 31 : 15, 8, Z_DEFAULT_STRATEGY);
  std::vector<std::byte> out(deflateBound(&z, uLong(in.size())) + 32);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data()));
  z.avail_in = uInt(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  if (deflate(&z, Z_FINISH) != Z_STREAM_END) throw std::runtime_error("deflate failed");
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

void zarr_chunk_seeds(std::vector<Seed>& out) {
  // A 4x4x4 chunk of u16 (dtype byte 1: "<u2"; shape bytes 3 -> 4 voxels).
  std::vector<std::byte> chunk;
  for (int i = 0; i < 64; ++i) {
    const int v = i < 16 ? 0 : i * 37;
    chunk.push_back(std::byte(v & 0xFF));
    chunk.push_back(std::byte(v >> 8));
  }
  const char* names[] = {"none", "blosc-lz4", "lz4", "zstd", "zlib", "gzip", "blosc-zstd"};
  for (int c = 0; c < 7; ++c) {
    std::vector<std::byte> enc;
    if (c == 0) {
      enc = chunk;
    } else if (c == 1 || c == 6) {
      enc.resize(chunk.size() + BLOSC_MAX_OVERHEAD);
      const int n =
          blosc_compress_ctx(5, c == 1 ? BLOSC_SHUFFLE : BLOSC_BITSHUFFLE, 2, chunk.size(),
                             chunk.data(), enc.data(), enc.size(), c == 1 ? "lz4" : "zstd", 0, 1);
      if (n <= 0) throw std::runtime_error("blosc compression failed");
      enc.resize(std::size_t(n));
    } else if (c == 2) {
      enc = {std::byte(chunk.size() & 0xFF), std::byte(chunk.size() >> 8), std::byte{0},
             std::byte{0}};
      const std::vector<std::byte> p = compress(Codec::lz4, 0, chunk);
      enc.insert(enc.end(), p.begin(), p.end());
    } else if (c == 3) {
      enc = compress(Codec::zstd, 0, chunk);
    } else {
      enc = deflate(chunk, c == 5);
    }
    std::vector<std::byte> b = {std::byte(c == 6 ? 1 : c), std::byte{1}, std::byte{3}, std::byte{3},
                                std::byte{3}};
    b.insert(b.end(), enc.begin(), enc.end());
    out.push_back({"zarr_chunk", std::string("seed-") + names[c] + ".bin", b, c == 0});
  }
}

// One entry of the ome_zarr target's in-memory store: KEY '\n' LENGTH '\n' BYTES.
void store_entry(std::vector<std::byte>& archive, const std::string& key,
                 const std::vector<std::byte>& bytes) {
  const std::vector<std::byte> head = text_bytes(key + "\n" + std::to_string(bytes.size()) + "\n");
  archive.insert(archive.end(), head.begin(), head.end());
  archive.insert(archive.end(), bytes.begin(), bytes.end());
}

// Chunk voxels of a little-endian array: value = (index * 37 + chunk * 11) % modulus.
std::vector<std::byte> chunk_voxels(std::size_t voxels, std::size_t width, int chunk, int modulus) {
  std::vector<std::byte> b;
  for (std::size_t i = 0; i < voxels; ++i) {
    const auto v = std::uint32_t((int(i) * 37 + chunk * 11) % modulus);
    if (width == 4) {
      const float f = float(v) / float(modulus);
      std::uint32_t bits;
      std::memcpy(&bits, &f, 4);
      for (int k = 3; k >= 0; --k) b.push_back(std::byte((bits >> (8 * k)) & 0xFF));  // ">f4"
    } else {
      for (std::size_t k = 0; k < width; ++k) b.push_back(std::byte((v >> (8 * k)) & 0xFF));
    }
  }
  return b;
}

void ome_zarr_seeds(std::vector<Seed>& out) {
  {
    // czyx u16, zstd, two datasets; some chunks missing (fill value 7).
    std::vector<std::byte> a;
    store_entry(a, ".zattrs", text_bytes(R"({"multiscales": [{"version": "0.4",
 "axes": [{"name": "c", "type": "channel"}, {"name": "z", "type": "space"},
          {"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
 "datasets": [
  {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 2, 1, 1]}]},
  {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [1, 2, 2, 2]}]}]}]})"));
    store_entry(a, "0/.zarray", text_bytes(R"({"zarr_format": 2, "shape": [2, 5, 10, 12],
 "chunks": [1, 5, 8, 8], "dtype": "<u2", "order": "C", "compressor": {"id": "zstd"},
 "fill_value": 7, "filters": null})"));
    store_entry(a, "1/.zarray", text_bytes(R"({"zarr_format": 2, "shape": [2, 5, 5, 6],
 "chunks": [1, 5, 5, 6], "dtype": "<u2", "order": "C", "compressor": null,
 "fill_value": 7, "filters": null})"));
    int n = 0;
    for (const char* key : {"0/0.0.0.0", "0/0.0.1.1", "0/1.0.0.1", "0/1.0.1.0"}) {
      store_entry(a, key, compress(Codec::zstd, 0, chunk_voxels(320, 2, n++, 4000)));
    }
    store_entry(a, "1/0.0.0.0", chunk_voxels(150, 2, 9, 4000));
    out.push_back({"ome_zarr", "seed-czyx-u16-zstd.store", a, false});
  }
  {
    // A bare root array, zyx u8, uncompressed, '/' separated chunk keys.
    std::vector<std::byte> a;
    store_entry(a, ".zarray", text_bytes(R"({"zarr_format": 2, "shape": [5, 6, 7],
 "chunks": [3, 3, 4], "dtype": "|u1", "order": "C", "compressor": null, "fill_value": 3,
 "dimension_separator": "/"})"));
    int n = 0;
    for (const char* key : {"0/0/0", "0/1/1", "1/0/1"}) {
      store_entry(a, key, chunk_voxels(36, 1, n++, 256));
    }
    out.push_back({"ome_zarr", "seed-bare-zyx-u8.store", a});
  }
  {
    // yx big-endian f32 in blosc, with an omero window (the value range).
    std::vector<std::byte> a;
    store_entry(a, ".zattrs", text_bytes(R"({"multiscales": [{"version": "0.4", "name": "yx",
 "axes": [{"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
 "datasets": [{"path": "s0", "coordinateTransformations": [{"type": "scale",
   "scale": [0.5, 0.5]}]}]}],
 "omero": {"channels": [{"label": "f", "color": "FFFFFF", "window": {"start": 0, "end": 1}}]}})"));
    store_entry(a, "s0/.zarray", text_bytes(R"({"zarr_format": 2, "shape": [9, 10],
 "chunks": [4, 4], "dtype": ">f4", "order": "C", "compressor": {"id": "blosc", "cname": "lz4",
 "clevel": 5, "shuffle": 1}, "fill_value": "NaN", "filters": null})"));
    int n = 0;
    for (const char* key : {"s0/0.0", "s0/1.2", "s0/2.1"}) {
      const std::vector<std::byte> raw = chunk_voxels(16, 4, n++, 100);
      std::vector<std::byte> enc(raw.size() + BLOSC_MAX_OVERHEAD);
      const int m = blosc_compress_ctx(5, BLOSC_SHUFFLE, 4, raw.size(), raw.data(), enc.data(),
                                       enc.size(), "lz4", 0, 1);
      if (m <= 0) throw std::runtime_error("blosc compression failed");
      enc.resize(std::size_t(m));
      store_entry(a, key, enc);
    }
    out.push_back({"ome_zarr", "seed-yx-f32-blosc.store", a, false});
  }
}

void png_seeds(const fs::path& scratch, std::vector<Seed>& out) {
  fs::create_directories(scratch);
  const glm::uvec2 sizes[] = {{1, 1}, {7, 3}, {16, 16}};
  for (const glm::uvec2 s : sizes) {
    Image img(s.x, s.y);
    for (std::uint32_t y = 0; y < s.y; ++y) {
      for (std::uint32_t x = 0; x < s.x; ++x) {
        img.at(x, y) = glm::vec4(float(x) / float(s.x), float(y) / float(s.y),
                                 float((x + y) % 3) / 2.0f, (x % 2) != 0 ? 1.0f : 0.5f);
      }
    }
    const std::string name = "seed-" + std::to_string(s.x) + "x" + std::to_string(s.y) + ".png";
    write_png(img, (scratch / name).string());
    out.push_back({"png", name, file_bytes(scratch / name), false});
  }
}

void nifti_file_seeds(std::vector<Seed>& out) {
  NiftiFields a;
  a.dim[1] = 4, a.dim[2] = 4, a.dim[3] = 2;
  std::vector<std::byte> fa = nifti(a);
  for (int i = 0; i < 32; ++i) fa.push_back(std::byte(i * 7));
  out.push_back({"nifti_file", "seed-u8-4x4x2.nii", fa});
  out.push_back({"nifti_file", "seed-u8-4x4x2.nii.gz", deflate(fa, true), false});
  NiftiFields b;
  b.big = true;
  b.dim[0] = 4, b.dim[1] = 3, b.dim[2] = 3, b.dim[3] = 2, b.dim[4] = 2;
  b.datatype = 4, b.bitpix = 16;
  b.slope = 2.0f, b.inter = -100.0f;
  std::vector<std::byte> fb = nifti(b);
  for (int i = 0; i < 36; ++i) {
    const auto v = std::int16_t(i * 300 - 5000);
    fb.push_back(std::byte((std::uint16_t(v) >> 8) & 0xFF));
    fb.push_back(std::byte(std::uint16_t(v) & 0xFF));
  }
  out.push_back({"nifti_file", "seed-i16-be-scaled-2vol.nii", fb});
  NiftiFields c;
  c.dim[1] = 5, c.dim[2] = 2, c.dim[3] = 1;
  c.datatype = 16, c.bitpix = 32;
  std::vector<std::byte> fc = nifti(c);
  for (int i = 0; i < 10; ++i) {
    const float f = i == 3 ? std::numeric_limits<float>::quiet_NaN() : float(i) * 0.25f;
    std::byte raw[4];
    std::memcpy(raw, &f, 4);
    fc.insert(fc.end(), raw, raw + 4);
  }
  out.push_back({"nifti_file", "seed-f32-nan.nii", fc});
  // NIfTI-2, 4-D (3 timepoints) with an sform that flips x and swaps y and z: the reordering path.
  Nifti2Fields d;
  d.dim[0] = 4, d.dim[1] = 4, d.dim[2] = 3, d.dim[3] = 2, d.dim[4] = 3;
  d.sform = 2;
  const double srow[12] = {-1, 0, 0, 3, 0, 0, 2, 0, 0, 1.5, 0, 0};
  std::memcpy(d.srow, srow, sizeof srow);
  std::vector<std::byte> fd = nifti2(d);
  for (int i = 0; i < 72; ++i) fd.push_back(std::byte(i * 3));
  out.push_back({"nifti_file", "seed-nifti2-4d-sform-permuted.nii", fd});
}

void nrrd_file_seeds(std::vector<Seed>& out) {
  std::vector<std::byte> a = text_bytes(
      "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 3 2\nencoding: raw\n"
      "spacings: 1 1 3\n\n");
  for (int i = 0; i < 24; ++i) a.push_back(std::byte(i * 10));
  out.push_back({"nrrd_file", "seed-u8-raw.nrrd", a});
  std::vector<std::byte> floats;
  for (int i = 0; i < 36; ++i) {
    const float f = float(i) / 8.0f;
    std::uint32_t bits;
    std::memcpy(&bits, &f, 4);
    for (int k = 3; k >= 0; --k) floats.push_back(std::byte((bits >> (8 * k)) & 0xFF));
  }
  std::vector<std::byte> b = text_bytes(
      "NRRD0005\ntype: float\ndimension: 4\nsizes: 2 3 3 2\n"
      "kinds: vector domain domain domain\nendian: big\nencoding: gzip\n"
      "space directions: none (0.5,0,0) (0,0.5,0) (0,0,2)\n\n");
  const std::vector<std::byte> gz = deflate(floats, true);
  b.insert(b.end(), gz.begin(), gz.end());
  out.push_back({"nrrd_file", "seed-f32-gzip-vector.nrrd", b, false});
  std::vector<std::byte> c = text_bytes(
      "NRRD0004\ntype: ushort\ndimension: 4\nsizes: 3 2 2 2\n"
      "kinds: domain domain domain list\nendian: little\nencoding: raw\nbyte skip: -1\n\n"
      "padding before the data\n");
  for (int i = 0; i < 24; ++i) {
    c.push_back(std::byte((i * 999) & 0xFF));
    c.push_back(std::byte((i * 999) >> 8));
  }
  out.push_back({"nrrd_file", "seed-u16-list-byteskip.nrrd", c});
}

// A multi-page TIFF through libtiff itself (strips, optional deflate), one page per z slice.
std::vector<std::byte> tiff_file(const fs::path& path, std::uint32_t w, std::uint32_t h,
                                 std::uint32_t pages, int bits, int format, bool deflate) {
  TIFF* t = TIFFOpen(path.c_str(), "w");
  if (t == nullptr) throw std::runtime_error("TIFFOpen failed");
  const std::size_t bytes = std::size_t(bits / 8);
  for (std::uint32_t p = 0; p < pages; ++p) {
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, w);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, h);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, format);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 2);
    TIFFSetField(t, TIFFTAG_COMPRESSION, deflate ? COMPRESSION_ADOBE_DEFLATE : COMPRESSION_NONE);
    if (pages > 1) {
      TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
      TIFFSetField(t, TIFFTAG_PAGENUMBER, p, pages);
    }
    std::vector<std::byte> row(w * bytes);
    for (std::uint32_t y = 0; y < h; ++y) {
      for (std::uint32_t x = 0; x < w; ++x) {
        const std::uint32_t v = (x * 13 + y * 7 + p * 29) % 200;
        if (format == SAMPLEFORMAT_IEEEFP) {
          const float f = float(v) / 200.0f;
          std::memcpy(row.data() + x * 4, &f, 4);
        } else {
          for (std::size_t k = 0; k < bytes; ++k)
            row[x * bytes + k] = std::byte((v >> (8 * k)) & 0xFF);
        }
      }
      if (TIFFWriteScanline(t, row.data(), y, 0) < 0) throw std::runtime_error("TIFF write failed");
    }
    TIFFWriteDirectory(t);
  }
  TIFFClose(t);
  return file_bytes(path);
}

void tiff_seeds(const fs::path& scratch, std::vector<Seed>& out) {
  fs::create_directories(scratch);
  out.push_back({"tiff_file", "seed-u8-3pages.tif",
                 tiff_file(scratch / "a.tif", 6, 5, 3, 8, SAMPLEFORMAT_UINT, false), false});
  out.push_back({"tiff_file", "seed-u16-deflate.tif",
                 tiff_file(scratch / "b.tif", 9, 4, 2, 16, SAMPLEFORMAT_UINT, true), false});
  out.push_back({"tiff_file", "seed-f32.tif",
                 tiff_file(scratch / "c.tif", 4, 4, 1, 32, SAMPLEFORMAT_IEEEFP, false), false});
}

}  // namespace

void format_seeds(const fs::path& scratch, std::vector<Seed>& out) {
  zarr_meta_seeds(out);
  zarr_chunk_seeds(out);
  ome_seeds(out);
  nifti_seeds(out);
  nifti2_seeds(out);
  nrrd_seeds(out);
  ome_zarr_seeds(out);
  png_seeds(scratch / "png", out);
  nifti_file_seeds(out);
  nrrd_file_seeds(out);
  tiff_seeds(scratch / "tiff", out);
}

}  // namespace resoct::fuzz::seeds
