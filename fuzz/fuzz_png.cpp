// Fuzz target: read_png, the reader of reference images and tool inputs. The input is the whole
// file. A decoded image must have the size its header announced, within Image's limits. As for
// the brick store, each input also runs with every chunk CRC recomputed (libpng rejects a
// critical chunk with a wrong CRC, which would hide everything behind the header).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <zlib.h>

#include "fuzz_support.hpp"
#include "resoct/backend/image.hpp"

namespace {

std::vector<std::uint8_t> with_valid_crcs(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> b(data, data + size);
  std::size_t at = 8;  // after the signature: length, type, data, CRC per chunk
  while (at + 12 <= b.size()) {
    const std::size_t len = std::size_t(b[at]) << 24 | std::size_t(b[at + 1]) << 16 |
                            std::size_t(b[at + 2]) << 8 | std::size_t(b[at + 3]);
    if (len > b.size() - at - 12) break;
    const uLong crc = crc32(0L, b.data() + at + 4, uInt(len + 4));
    for (int i = 0; i < 4; ++i)
      b[at + 8 + len + std::size_t(i)] = std::uint8_t(crc >> (24 - 8 * i));
    at += len + 12;
  }
  return b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  static fuzz::ScratchFile file("resoct-fuzz-png");
  const auto run = [&](const std::uint8_t* bytes, std::size_t n) {
    file.write(bytes, n);
    fuzz::errors_only([&] {
      const Image img = read_png(file.path());
      if (img.width() == 0 || img.height() == 0 || img.width() > 65536 || img.height() > 65536 ||
          img.pixels().size() != std::size_t(img.width()) * img.height()) {
        fuzz::fail("decoded image has an impossible size");
      }
    });
  };
  run(data, size);
  const std::vector<std::uint8_t> fixed = with_valid_crcs(data, size);
  if (!std::equal(fixed.begin(), fixed.end(), data)) run(fixed.data(), fixed.size());
  return 0;
}
