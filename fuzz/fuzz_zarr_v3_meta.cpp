// Fuzz target: zarr v3 array `zarr.json`. A parsed array must satisfy what the parser promises
// (equal ranks, a read unit within kMaxZarrChunkBytes, a shard of at most kMaxZarrShardChunks
// inner chunks that divide it), and the derived keys must not overflow or throw.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "resoct/io/formats/zarr_v3.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  fuzz::errors_only([&] {
    const ZarrArrayMeta m = parse_zarr_v3_array_meta(json, "fuzz/zarr.json");
    if (!m.v3 || m.zarr_format != 3) fuzz::fail("v3 layout missing");
    if (m.shape.empty() || m.shape.size() != m.chunks.size()) fuzz::fail("rank mismatch accepted");
    if (m.chunk_bytes() == 0 || m.chunk_bytes() > kMaxZarrChunkBytes) {
      fuzz::fail("read unit outside 1..kMaxZarrChunkBytes accepted");
    }
    const auto& shard = m.v3->shard_shape;
    if (!shard.empty()) {
      std::uint64_t per = 1;
      for (std::size_t i = 0; i < shard.size(); ++i) {
        if (shard[i] % m.chunks[i] != 0) fuzz::fail("inner chunk not dividing the shard");
        per *= shard[i] / m.chunks[i];
      }
      if (per > kMaxZarrShardChunks) fuzz::fail("shard index above the bound accepted");
      (void)zarr_shard_index_bytes(*m.v3->codecs[0].sharding, per, "fuzz");
    }
    const std::vector<std::uint64_t> grid = m.chunk_grid();
    std::vector<std::uint64_t> last(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) last[i] = grid[i] - 1;
    (void)m.chunk_key(last);
  });
  return 0;
}
