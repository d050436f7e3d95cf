// Fuzz target: decoding one stored zarr chunk. The metadata comes from the first 5 bytes so the
// fuzzer spends its time in the codecs, not in JSON:
//   byte 0: compressor (value % 6: none, blosc, lz4, zstd, zlib, gzip)
//   byte 1: dtype (value % 5: |u1, <u2, >u2, <f4, >f4)
//   bytes 2..4: chunk shape, (value % 32) + 1 per axis (at most 128 KiB decoded)
// and the rest is the encoded chunk. A decoded chunk must have exactly chunk_bytes() bytes.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/formats/zarr_array.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  if (size < 5) return 0;
  ZarrArrayMeta m;
  m.compressor = ZarrCompressor(data[0] % 6);
  switch (data[1] % 5) {
    case 0: m.type = VoxelType::u8; break;
    case 1: m.type = VoxelType::u16; break;
    case 2: m.type = VoxelType::u16, m.endian = Endian::big; break;
    case 3: m.type = VoxelType::f32; break;
    default: m.type = VoxelType::f32, m.endian = Endian::big; break;
  }
  for (int i = 2; i < 5; ++i) m.chunks.push_back(std::uint64_t(data[i] % 32) + 1);
  m.shape = m.chunks;
  const std::span<const std::byte> encoded(reinterpret_cast<const std::byte*>(data + 5), size - 5);
  fuzz::errors_only([&] {
    const std::vector<std::byte> out = decode_zarr_chunk(m, encoded, "fuzz/0.0.0");
    if (out.size() != m.chunk_bytes()) fuzz::fail("decoded chunk has the wrong size");
  });
  return 0;
}
