// Fuzz target: the whole brick store read path. The input is a complete .rbs file; opening it
// decodes and validates the header, the brick index and the zstd metadata section, then every
// brick (bounded, see below) is decoded and every query the renderer makes is asked.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/brick_store.hpp"

namespace {

using namespace resoct;

// A valid header may describe bricks of up to 1026^3 f32 voxels; reading those would measure
// the allocator, not the decoder. The seeds use bricks of a few hundred bytes.
constexpr std::uint64_t kMaxBrickBytes = std::uint64_t(1) << 20;
constexpr std::uint64_t kMaxBricks = 512;

void exercise(const BrickStoreSource& store) {
  const BrickHierarchy& h = store.hierarchy();
  const VolumeDesc& v = h.volume();
  const std::uint64_t brick_bytes = h.layout().padded_voxels() * voxel_size(v.type);
  const StoreStats& stats = store.stats();
  if (stats.levels.size() != h.level_count()) fuzz::fail("stats and hierarchy disagree on levels");
  std::vector<std::byte> buf;
  if (brick_bytes <= kMaxBrickBytes) buf.resize(std::size_t(brick_bytes));
  std::uint64_t visited = 0;
  for (std::uint32_t c = 0; c < v.channels; ++c) {
    for (std::uint64_t i = 0; i < h.bricks_per_channel() && visited < kMaxBricks; ++i, ++visited) {
      const BrickKey key = h.key_from_linear(c, i);
      const BrickMeta m = store.brick_meta(key);
      (void)m;
      // A damaged payload fails only its own brick; keep reading the others.
      if (!buf.empty()) fuzz::errors_only([&] { store.read_brick(key, buf); });
    }
    const Box3 all{glm::i64vec3(0), glm::i64vec3(v.extent)};
    const RegionMeta whole = store.region_meta(c, all);
    (void)whole;
    // A corner box and one reaching past the volume (queries clamp).
    const Box3 corner{glm::i64vec3(v.extent) / std::int64_t(2),
                      glm::i64vec3(v.extent) + std::int64_t(3)};
    (void)store.region_meta(c, corner);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::ScratchFile file("resoct-fuzz-store");
  file.write(data, size);
  fuzz::errors_only([&] {
    const BrickStoreSource store(file.path());
    exercise(store);
  });
  return 0;
}
