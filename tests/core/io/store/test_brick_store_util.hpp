#pragma once
// Helpers shared by the brick store tests: a self-deleting temporary directory, whole-file I/O,
// little-endian patching of stored files (written from the documented layout, not from the
// store's own encoder), and the test volumes.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <zlib.h>

#include "resoct/volume/volume_desc.hpp"

namespace resoct::test {

class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "resoct-store-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }
  /// Names of all entries in the directory.
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(path_))
      out.push_back(e.path().filename().string());
    return out;
  }

 private:
  std::filesystem::path path_;
};

inline std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

inline void write_bytes(const std::string& path, const std::vector<std::uint8_t>& b) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

inline std::uint64_t get_le(const std::vector<std::uint8_t>& b, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= std::uint64_t(b.at(at + i)) << (8 * i);
  return v;
}

inline void put_le(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) b.at(at + i) = std::uint8_t(v >> (8 * i));
}

inline std::uint32_t zlib_crc(const std::vector<std::uint8_t>& b, std::size_t at, std::size_t n) {
  return std::uint32_t(::crc32(0, b.data() + at, uInt(n)));
}

// Documented version-1 layout (docs/brick-store-format.md).
namespace layout {
inline constexpr std::size_t version = 8, header_size = 12, flags = 16, extent = 24, channels = 72,
                             brick_size = 76, index_crc = 108, payload_offset = 120,
                             payload_size = 128, index_offset = 136, index_size = 144,
                             metadata_offset = 152, metadata_size = 160, metadata_crc = 176,
                             data_type = 180;
inline constexpr std::size_t entry_size = 40, entry_offset = 0, entry_size_field = 8,
                             entry_crc = 12, entry_flags = 32;
}  // namespace layout

/// Recomputes the header CRC after a test patched header fields.
inline void fix_header_crc(std::vector<std::uint8_t>& b) {
  const std::size_t hs = std::size_t(get_le(b, layout::header_size, 4));
  put_le(b, hs - 4, zlib_crc(b, 0, hs - 4), 4);
}

/// Recomputes the index CRC (and then the header CRC) after a test patched index entries.
inline void fix_index_crc(std::vector<std::uint8_t>& b) {
  const std::size_t io = std::size_t(get_le(b, layout::index_offset, 8));
  const std::size_t is = std::size_t(get_le(b, layout::index_size, 8));
  put_le(b, layout::index_crc, zlib_crc(b, io, is), 4);
  fix_header_crc(b);
}

/// Deterministic test data: an all-zero slab (constant bricks), a smooth ramp, hashed noise,
/// and for f32 scattered NaN and negative values.
inline double test_value(VoxelType t, std::uint32_t c, const glm::u64vec3& p,
                         const glm::u64vec3& extent) {
  if (p.x < extent.x / 2) return 0.0;
  std::uint64_t h = p.x * 0x9E3779B97F4A7C15ull ^ p.y * 0xC2B2AE3D27D4EB4Full ^
                    p.z * 0x165667B19E3779F9ull ^ (c + 1) * 0x27D4EB2F165667C5ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  const double noise = double(h % 1000) / 1000.0;
  const double ramp =
      double(p.x + 2 * p.y + 3 * p.z) / double(extent.x + 2 * extent.y + 3 * extent.z);
  switch (t) {
    case VoxelType::u8: return 200.0 * ramp + 50.0 * noise * (c + 1) / 4.0;
    case VoxelType::u16: return 60000.0 * ramp + 5000.0 * noise;
    case VoxelType::f32:
      if (h % 53 == 0) return std::nan("");
      return ramp - 0.25 + 0.01 * noise * double(c + 1);
  }
  return 0.0;
}

}  // namespace resoct::test
