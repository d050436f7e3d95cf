#include "resoct/io/storage/checksum.hpp"

#include <algorithm>

#include <zlib.h>

namespace resoct {

std::uint32_t crc32(std::span<const std::byte> data, std::uint32_t crc) noexcept {
  // zlib takes uInt lengths; feed large spans in chunks so that nothing is silently cut off.
  constexpr std::size_t kChunk = std::size_t(1) << 30;
  uLong c = crc;
  const auto* p = reinterpret_cast<const Bytef*>(data.data());
  std::size_t left = data.size();
  while (left > 0) {
    const std::size_t n = std::min(left, kChunk);
    c = ::crc32(c, p, static_cast<uInt>(n));
    p += n;
    left -= n;
  }
  return static_cast<std::uint32_t>(c);
}

}  // namespace resoct
