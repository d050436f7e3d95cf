// Fuzz target: decoding one stored zarr chunk. The metadata comes from the first 5 bytes so the
// fuzzer spends its time in the codecs, not in JSON:
//   byte 0: compressor (value % 6: none, blosc, lz4, zstd, zlib, gzip)
//   byte 1: dtype: bit 0 the byte order (1: big endian), (value >> 1) % 8 the stored type (u8,
//           u16, f32, i8, i16, i32, u32, f64; the voxel type follows as data_mapping says)
//   bytes 2..4: chunk shape, (value % 32) + 1 per axis (at most 128 KiB decoded)
// and the rest is the encoded chunk. A decoded chunk must have exactly chunk_bytes() bytes.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/io/formats/zarr_array.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  if (size < 5) return 0;
  ZarrArrayMeta m;
  m.compressor = ZarrCompressor(data[0] % 6);
  // Stored and voxel type must agree as the metadata parser makes them: a hand-set voxel type
  // alone (the target's form before signed and wide types) left the stored type at u8 and made
  // inconsistent metadata, which the first run to ten million executions reported as a chunk of
  // the wrong size (fuzz/regressions/zarr_chunk/).
  constexpr DataType kTypes[] = {DataType::u8,  DataType::u16, DataType::f32, DataType::i8,
                                 DataType::i16, DataType::i32, DataType::u32, DataType::f64};
  m.data_type = kTypes[(data[1] >> 1) % 8];
  m.endian = (data[1] & 1) != 0 ? Endian::big : Endian::little;
  m.type = data_mapping(m.data_type).stored;
  for (int i = 2; i < 5; ++i) m.chunks.push_back(std::uint64_t(data[i] % 32) + 1);
  m.shape = m.chunks;
  const std::span<const std::byte> encoded(reinterpret_cast<const std::byte*>(data + 5), size - 5);
  fuzz::errors_only([&] {
    const std::vector<std::byte> out = decode_zarr_chunk(m, encoded, "fuzz/0.0.0");
    if (out.size() != m.chunk_bytes()) fuzz::fail("decoded chunk has the wrong size");
  });
  return 0;
}
