// Fuzz target: the index of a zarr v3 shard (sharding_indexed), index at the end, [bytes,
// crc32c] index codecs. Input: 1 byte of inner chunks per shard (1..64), then the shard's bytes.
// Accepted entries must lie inside the shard, outside the index and not overlap.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_support.hpp"
#include "resoct/io/formats/zarr_v3.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  if (size < 1) return 0;
  const std::uint64_t n = 1 + data[0] % 64;
  const std::span<const std::byte> shard(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  ZarrShardingCodec s;
  s.chunk_shape = {1};
  ZarrCodec bytes, crc;
  bytes.kind = ZarrCodecKind::bytes;
  crc.kind = ZarrCodecKind::crc32c;
  s.index_codecs = {bytes, crc};
  fuzz::errors_only([&] {
    const std::uint64_t len = zarr_shard_index_bytes(s, n, "fuzz");
    if (shard.size() < len) return;
    const std::uint64_t at = shard.size() - len;
    const auto e =
        parse_zarr_shard_index(shard.subspan(at), s, n, at, shard.size(), 1 << 20, "fuzz/shard");
    if (e.size() != n) fuzz::fail("entry count");
    for (const ZarrShardEntry& x : e) {
      if (x.empty()) continue;
      if (x.offset + x.nbytes > at && x.nbytes != 0) fuzz::fail("entry over the index accepted");
    }
  });
  return 0;
}
