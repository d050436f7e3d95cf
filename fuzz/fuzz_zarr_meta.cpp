// Fuzz target: zarr v2 `.zarray` metadata. A parsed array must satisfy what the header promises
// (equal ranks, sizes >= 1, a chunk within kMaxZarrChunkBytes), and the derived quantities the
// zarr source computes from it must not overflow or throw.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "resoct/io/formats/zarr_array.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  fuzz::errors_only([&] {
    const ZarrArrayMeta m = parse_zarr_array_meta(json, "fuzz/.zarray");
    if (m.shape.empty() || m.shape.size() != m.chunks.size()) fuzz::fail("rank mismatch accepted");
    for (std::size_t i = 0; i < m.shape.size(); ++i) {
      if (m.shape[i] == 0 || m.chunks[i] == 0) fuzz::fail("zero size accepted");
    }
    if (m.chunk_bytes() == 0 || m.chunk_bytes() > kMaxZarrChunkBytes) {
      fuzz::fail("chunk size outside 1..kMaxZarrChunkBytes accepted");
    }
    const std::vector<std::uint64_t> grid = m.chunk_grid();
    std::vector<std::uint64_t> last(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) last[i] = grid[i] - 1;
    (void)m.chunk_key(last);
  });
  return 0;
}
