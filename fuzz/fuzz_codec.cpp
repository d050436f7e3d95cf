// Fuzz target: payload decoding with an announced size, as the brick store decodes a brick.
// Input: byte 0 selects the codec (bit 0: lz4 or zstd), bytes 1..3 give the announced decoded
// size (little-endian 24 bits modulo 128 KiB: a padded 32^3 u16 brick with halo is 78 KiB, and
// mutated sizes of megabytes made the target allocate more than it decoded, at ~60 runs/s), the
// rest is the payload. A payload that decodes must re-encode and decode to the same bytes.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/io/storage/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  if (size < 4) return 0;
  const Codec codec = (data[0] & 1u) != 0 ? Codec::zstd : Codec::lz4;
  const std::size_t announced =
      (std::size_t(data[1]) | std::size_t(data[2]) << 8 | std::size_t(data[3]) << 16) % (1u << 17);
  const std::span<const std::byte> payload(reinterpret_cast<const std::byte*>(data + 4), size - 4);
  std::vector<std::byte> out(announced);
  if (!fuzz::errors_only([&] { decompress_exact(codec, payload, out, "fuzz", 0); })) return 0;
  const std::vector<std::byte> packed = compress(codec, 0, out);
  std::vector<std::byte> again(announced);
  decompress_exact(codec, packed, again, "round-trip", 0);
  if (announced != 0 && std::memcmp(again.data(), out.data(), announced) != 0) {
    fuzz::fail("decoded payload does not survive compress + decompress");
  }
  return 0;
}
