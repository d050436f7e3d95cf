// Fuzz target: the whole brick store read path. The input is a complete .rbs file; opening it
// decodes and validates the header, the brick index and the zstd metadata section, then every
// brick (bounded, see below) is decoded and every query the renderer makes is asked.
// Almost every mutation breaks a CRC-32, which would stop the fuzzer at the first checksum; so
// each input runs twice: as given (the checksum checks) and with every checksum recomputed
// from the mutated fields (everything behind them).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/storage/checksum.hpp"
#include "resoct/io/store/format.hpp"

namespace {

using namespace resoct;

// A valid header may describe bricks of up to 1026^3 f32 voxels; reading those would measure
// the allocator, not the decoder. The seeds use bricks of a few hundred bytes.
constexpr std::uint64_t kMaxBrickBytes = std::uint64_t(1) << 20;
constexpr std::uint64_t kMaxBricks = 512;

std::uint64_t get_le(const std::vector<std::uint8_t>& b, std::uint64_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= std::uint64_t(b[std::size_t(at) + i]) << (8 * i);
  return v;
}

void put_crc(std::vector<std::uint8_t>& b, std::uint64_t at, std::uint64_t from,
             std::uint64_t size) {
  const std::uint32_t crc = crc32(std::as_bytes(std::span(b).subspan(from, size)));
  for (int i = 0; i < 4; ++i) b[std::size_t(at) + i] = std::uint8_t(crc >> (8 * i));
}

bool inside(std::uint64_t offset, std::uint64_t size, std::uint64_t file) {
  return offset <= file && size <= file - offset;
}

// The input with every checksum that its (possibly mutated) offsets let us find recomputed:
// payloads, then the index that holds their CRCs, the metadata, and last the header.
std::vector<std::uint8_t> with_valid_checksums(const std::uint8_t* data, std::size_t size) {
  namespace hdr = detail::hdr;
  std::vector<std::uint8_t> b(data, data + size);
  if (size < hdr::fixed_size) return b;
  const std::uint64_t hs = get_le(b, hdr::header_size, 4);
  const std::uint64_t index = get_le(b, hdr::index_offset, 8);
  const std::uint64_t index_size = get_le(b, hdr::index_size, 8);
  const std::uint64_t meta = get_le(b, hdr::metadata_offset, 8);
  const std::uint64_t meta_size = get_le(b, hdr::metadata_size, 8);
  if (inside(index, index_size, size)) {
    for (std::uint64_t e = index; e + detail::kIndexEntrySize <= index + index_size;
         e += detail::kIndexEntrySize) {
      const std::uint64_t off = get_le(b, e, 8), n = get_le(b, e + 8, 4);
      if (inside(off, n, size)) put_crc(b, e + 12, off, n);
    }
    put_crc(b, hdr::index_crc, index, index_size);
  }
  if (inside(meta, meta_size, size)) put_crc(b, hdr::metadata_crc, meta, meta_size);
  const std::uint64_t flags = get_le(b, hdr::flags, 4);
  const std::uint64_t channels = get_le(b, hdr::channels, 4);
  if ((flags & detail::kFlagBrickErrors) != 0 && channels <= kMaxChannels) {
    const std::uint64_t f = detail::error_fields_at(std::uint32_t(channels), std::uint32_t(flags));
    if (f + detail::kErrorFieldsSize <= size) {
      const std::uint64_t errors = get_le(b, f + detail::kErrorFieldOffset, 8);
      const std::uint64_t errors_size = get_le(b, f + detail::kErrorFieldSize, 8);
      if (inside(errors, errors_size, size)) {
        put_crc(b, f + detail::kErrorFieldCrc, errors, errors_size);
      }
    }
  }
  if (hs >= hdr::fixed_size && hs <= size) put_crc(b, hs - 4, 0, hs - 4);
  return b;
}

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
      // Stored errors only: measuring would read up to 2^24 level-0 voxels per brick.
      if (!buf.empty() && stats.brick_errors) {
        const double e = store.brick_error(key, buf);
        if (!(e >= 0.0 && e <= 1.0)) fuzz::fail("a stored brick error outside [0, 1]");
      }
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
  const auto run = [&](const std::uint8_t* bytes, std::size_t n) {
    file.write(bytes, n);
    fuzz::errors_only([&] {
      const BrickStoreSource store(file.path());
      exercise(store);
    });
  };
  run(data, size);
  const std::vector<std::uint8_t> fixed = with_valid_checksums(data, size);
  if (!std::equal(fixed.begin(), fixed.end(), data)) run(fixed.data(), fixed.size());
  return 0;
}
