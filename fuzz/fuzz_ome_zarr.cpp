// Fuzz target: a whole OME-Zarr image through open_ome_zarr, as the zarr and HTTP sources read
// it: `.zattrs`, every dataset's `.zarray`, chunks (decoded and cut into bricks), fill values
// for missing chunks, the level-0 passes at open (small arrays) or lazy region metadata (large
// ones, whatever size they declare), then bricks, brick metadata and region metadata. The input is
// an in-memory store, a sequence of entries
//   KEY '\n' DECIMAL_LENGTH '\n' BYTES
// (parsing stops at the first malformed entry), so seeds stay mostly text.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_support.hpp"
#include "resoct/io/formats/ome_zarr.hpp"

namespace {

using namespace resoct;

class MemoryStore final : public ByteStore {
 public:
  explicit MemoryStore(std::string_view in) {
    while (!in.empty()) {
      const std::size_t k = in.find('\n');
      if (k == std::string_view::npos) return;
      const std::string_view key = in.substr(0, k);
      in.remove_prefix(k + 1);
      const std::size_t l = in.find('\n');
      if (l == std::string_view::npos) return;
      std::size_t n = 0;
      const auto [end, ec] = std::from_chars(in.data(), in.data() + l, n);
      if (ec != std::errc() || end != in.data() + l) return;
      in.remove_prefix(l + 1);
      if (n > in.size()) return;
      const auto* p = reinterpret_cast<const std::byte*>(in.data());
      objects_[std::string(key)] = std::vector<std::byte>(p, p + n);
      in.remove_prefix(n);
    }
  }

  std::optional<std::vector<std::byte>> get(std::string_view key,
                                            std::uint64_t max_bytes) const override {
    const auto it = objects_.find(std::string(key));
    if (it == objects_.end()) return std::nullopt;
    if (it->second.size() > max_bytes) {
      throw Error(ErrorCode::out_of_range,
                  location(key) + ": object larger than " + std::to_string(max_bytes) + " bytes");
    }
    return it->second;
  }

  std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                   std::uint64_t size) const override {
    const auto it = objects_.find(std::string(key));
    if (it == objects_.end()) throw Error(ErrorCode::io, location(key) + ": missing");
    const std::vector<std::byte>& b = it->second;
    if (offset > b.size() || size > b.size() - offset) {
      throw file_error(ErrorCode::truncated, location(key), offset, "range beyond the object");
    }
    return {b.begin() + std::ptrdiff_t(offset), b.begin() + std::ptrdiff_t(offset + size)};
  }

  std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                             std::uint64_t offset,
                                                             std::uint64_t size) const override {
    if (!objects_.contains(std::string(key))) return std::nullopt;
    return get_range(key, offset, size);
  }

  std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const override {
    const auto it = objects_.find(std::string(key));
    if (it == objects_.end()) return std::nullopt;
    const std::uint64_t n = it->second.size();
    if (size > n)
      throw file_error(ErrorCode::truncated, location(key), 0, "suffix beyond the object");
    return ObjectTail{get_range(key, n - size, size), n};
  }

  std::string location(std::string_view key) const override {
    return "mem://fuzz/" + std::string(key);
  }

  /// False when an array declares a chunk of more than `max_chunk` bytes: a missing chunk is
  /// materialized as fill value, so each read costs a chunk's bytes whatever the store holds.
  /// The declared array size is not bounded: above eager_scan_voxels opening reads metadata
  /// only and region metadata is computed lazily (docs/formats.md).
  bool small_enough(std::uint64_t max_chunk) const {
    for (const auto& object : objects_) {
      const std::string& key = object.first;
      if (!key.ends_with(".zarray")) continue;
      const std::string_view text(reinterpret_cast<const char*>(object.second.data()),
                                  object.second.size());
      ZarrArrayMeta m;
      if (!fuzz::errors_only([&] { m = parse_zarr_array_meta(text, key); })) continue;
      if (m.chunk_bytes() > max_chunk) return false;
    }
    return true;
  }

 private:
  std::map<std::string, std::vector<std::byte>> objects_;
};

constexpr std::uint64_t kMaxBricks = 64;

void exercise(const OmeZarrSource& src) {
  const BrickHierarchy& h = src.hierarchy();
  const VolumeDesc& v = h.volume();
  std::vector<std::byte> buf(std::size_t(h.layout().padded_voxels()) * voxel_size(v.type));
  const Box3 all{glm::i64vec3(0), glm::i64vec3(v.extent)};
  for (std::uint32_t c = 0; c < v.channels && c < 4; ++c) {
    for (std::uint64_t i = 0; i < h.bricks_per_channel() && i < kMaxBricks; ++i) {
      const BrickKey key = h.key_from_linear(c, i);
      // A damaged chunk fails the bricks cut from it; keep reading the others.
      fuzz::errors_only([&] {
        src.read_brick(key, buf);
        (void)src.brick_meta(key);
      });
    }
    (void)src.region_meta(c, all);
    // Small enough for the lazy path to read its blocks.
    (void)src.region_meta(c, Box3{glm::i64vec3(0), glm::i64vec3(10)});
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto store = std::make_shared<const MemoryStore>(
      std::string_view(reinterpret_cast<const char*>(data), size));
  if (!store->small_enough(std::uint64_t(1) << 20)) return 0;
  OmeZarrOptions options;
  // Small arrays take the eager path, larger ones the lazy one: both get exercised.
  options.pyramid.eager_scan_voxels = std::uint64_t(1) << 15;
  options.chunk_cache_bytes = 1 << 20;
  options.pyramid.cache_bytes = 1 << 20;
  options.pyramid.threads = 1;
  fuzz::errors_only([&] {
    const auto src = open_ome_zarr(store, BrickLayout{glm::uvec3(8), 1}, options);
    exercise(*src);
  });
  return 0;
}
