#include "io/formats/level0_scan.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

namespace resoct::detail {

namespace {

/// Tiles of level 0, block-aligned so that distinct tiles touch distinct metadata blocks.
struct Tiling {
  glm::u64vec3 extent;
  std::uint64_t edge;
  glm::u64vec3 count;

  Tiling(const glm::u64vec3& e, std::uint64_t tile_edge)
      : extent(e), edge(tile_edge), count((e + glm::u64vec3(tile_edge - 1)) / tile_edge) {}
  std::uint64_t size() const { return count.x * count.y * count.z; }
  Box3 box(std::uint64_t i) const {
    const glm::u64vec3 t{i % count.x, (i / count.x) % count.y, i / (count.x * count.y)};
    const glm::u64vec3 lo = t * edge;
    return Box3{glm::i64vec3(lo), glm::i64vec3(glm::min(lo + glm::u64vec3(edge), extent))};
  }
};

/// Runs fn(tile, channel, voxels) for every tile and channel on `threads` threads; the first
/// exception is rethrown after all threads stop.
template <typename Fn>
void for_each_tile(const VolumeDesc& desc, const LevelBoxReader& level0, std::uint64_t edge,
                   std::uint32_t threads, Fn&& fn) {
  const Tiling tiling(desc.extent, edge);
  const std::uint64_t jobs = tiling.size() * desc.channels;
  std::atomic<std::uint64_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    std::vector<std::byte> buf;
    while (!failed.load(std::memory_order_relaxed)) {
      const std::uint64_t j = next.fetch_add(1);
      if (j >= jobs) return;
      const auto channel = std::uint32_t(j % desc.channels);
      const Box3 box = tiling.box(j / desc.channels);
      buf.resize(std::size_t(box.volume()) * voxel_size(desc.type));
      try {
        level0(channel, box, buf);
        fn(box, channel, std::span<const std::byte>(buf));
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::uint32_t n = threads != 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
  n = std::uint32_t(std::min<std::uint64_t>(n, jobs));
  std::vector<std::thread> pool;
  for (std::uint32_t i = 1; i < n; ++i) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

template <typename T>
double value_at(const std::byte* p, std::size_t i) {
  T v;
  std::memcpy(&v, p + i * sizeof(T), sizeof(T));
  return double(v);
}

template <typename T>
void tile_minmax(std::span<const std::byte> voxels, double& lo, double& hi) {
  const std::size_t n = voxels.size() / sizeof(T);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = value_at<T>(voxels.data(), i);
    if (!std::isfinite(d)) continue;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
}

template <typename T>
void block_metas(const Box3& box, std::span<const std::byte> voxels, const ValueRange& r,
                 const std::vector<std::uint32_t>& lut, std::int64_t bs,
                 std::span<RegionMeta> meta) {
  const glm::i64vec3 s = box.size();
  const glm::i64vec3 b0 = box.lo / bs, b1 = (box.hi - std::int64_t(1)) / bs;
  const glm::i64vec3 nb = b1 - b0 + std::int64_t(1);
  for (std::int64_t z = 0; z < s.z; ++z) {
    for (std::int64_t y = 0; y < s.y; ++y) {
      const std::size_t row = std::size_t((z * s.y + y) * s.x);
      const std::int64_t by = (box.lo.y + y) / bs - b0.y, bz = (box.lo.z + z) / bs - b0.z;
      // One run of x per metadata block, so the block index is not divided out per voxel.
      for (std::int64_t bx = 0; bx < nb.x; ++bx) {
        RegionMeta& m = meta[std::size_t((bz * nb.y + by) * nb.x + bx)];
        const std::int64_t x0 = std::max<std::int64_t>(0, (b0.x + bx) * bs - box.lo.x);
        const std::int64_t x1 = std::min<std::int64_t>(s.x, (b0.x + bx + 1) * bs - box.lo.x);
        for (std::int64_t x = x0; x < x1; ++x) {
          T v;
          std::memcpy(&v, voxels.data() + (row + std::size_t(x)) * sizeof(T), sizeof(T));
          const double d = double(v);
          if constexpr (std::is_same_v<T, float>) {
            if (std::isnan(d)) continue;
            m.occupancy |= occupancy_bit(d, r);
          } else {
            m.occupancy |= lut.empty() ? occupancy_bit(d, r) : lut[std::size_t(v)];
          }
          m.min = std::min(m.min, d);
          m.max = std::max(m.max, d);
        }
      }
    }
  }
}

void tile_metadata(const Box3& box, std::span<const std::byte> voxels, VoxelType t,
                   const ValueRange& r, const std::vector<std::uint32_t>& lut,
                   std::uint32_t channel, MetadataPyramid& pyramid) {
  const auto bs = std::int64_t(pyramid.block_size());
  const glm::i64vec3 b0 = box.lo / bs, b1 = (box.hi - std::int64_t(1)) / bs;
  const glm::i64vec3 nb = b1 - b0 + std::int64_t(1);
  std::vector<RegionMeta> meta(std::size_t(nb.x * nb.y * nb.z));
  block_metadata(t, box, voxels, r, lut, pyramid.block_size(), meta);
  for (std::int64_t z = 0; z < nb.z; ++z) {
    for (std::int64_t y = 0; y < nb.y; ++y) {
      for (std::int64_t x = 0; x < nb.x; ++x) {
        pyramid.merge_block(channel, glm::u64vec3(b0 + glm::i64vec3(x, y, z)),
                            meta[std::size_t((z * nb.y + y) * nb.x + x)]);
      }
    }
  }
}

std::uint64_t tile_edge(std::uint32_t block) {
  return std::max<std::uint64_t>(block, 128);
}

}  // namespace

std::vector<std::uint32_t> occupancy_lut(VoxelType t, const ValueRange& r) {
  std::vector<std::uint32_t> lut;
  if (t == VoxelType::f32) return lut;
  // Integer types: the occupancy bit of every possible value, looked up instead of recomputed.
  lut.resize(t == VoxelType::u8 ? 256u : 65536u);
  const std::size_t n = lut.size();
  if (!(std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo < r.hi)) {
    for (std::size_t v = 0; v < n; ++v) lut[v] = occupancy_bit(double(v), r);
    return lut;
  }
  // For lo < hi the bin never decreases with the value (every step of occupancy_bit's arithmetic
  // rounds monotonically), so the table is at most 32 runs of one bit: each run's end is found by
  // bisection with occupancy_bit itself, about 500 evaluations instead of 65536 for u16 (a
  // measurable part of opening a small many-channel file, and of every fuzzed input).
  std::size_t v = 0;
  while (v < n) {
    const std::uint32_t bit = occupancy_bit(double(v), r);
    std::size_t same = v, other = n;  // bit at `same`; a different bit (or the end) at `other`
    while (other - same > 1) {
      const std::size_t mid = same + (other - same) / 2;
      (occupancy_bit(double(mid), r) == bit ? same : other) = mid;
    }
    std::fill(lut.begin() + std::ptrdiff_t(v), lut.begin() + std::ptrdiff_t(other), bit);
    v = other;
  }
  return lut;
}

void block_metadata(VoxelType t, const Box3& box, std::span<const std::byte> voxels,
                    const ValueRange& r, const std::vector<std::uint32_t>& lut, std::uint32_t block,
                    std::span<RegionMeta> out) {
  const auto bs = std::int64_t(block);
  switch (t) {
    case VoxelType::u8: block_metas<std::uint8_t>(box, voxels, r, lut, bs, out); break;
    case VoxelType::u16: block_metas<std::uint16_t>(box, voxels, r, lut, bs, out); break;
    case VoxelType::f32: block_metas<float>(box, voxels, r, lut, bs, out); break;
  }
}

std::vector<std::pair<double, double>> scan_finite_minmax(const VolumeDesc& desc,
                                                          const LevelBoxReader& level0,
                                                          std::uint32_t threads) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<double, double>> out(desc.channels, {inf, -inf});
  std::mutex m;
  for_each_tile(desc, level0, 128, threads,
                [&](const Box3&, std::uint32_t c, std::span<const std::byte> v) {
                  double lo = inf, hi = -inf;
                  switch (desc.type) {
                    case VoxelType::u8: tile_minmax<std::uint8_t>(v, lo, hi); break;
                    case VoxelType::u16: tile_minmax<std::uint16_t>(v, lo, hi); break;
                    case VoxelType::f32: tile_minmax<float>(v, lo, hi); break;
                  }
                  const std::lock_guard lock(m);
                  out[c].first = std::min(out[c].first, lo);
                  out[c].second = std::max(out[c].second, hi);
                });
  return out;
}

void fill_metadata(const VolumeDesc& desc, const LevelBoxReader& level0, MetadataPyramid& pyramid,
                   std::uint32_t threads) {
  // A table pays only for channels with more voxels than it has entries (65536 for u16): a small
  // file computes each voxel's bit instead of filling 256 KiB per channel.
  const std::uint64_t voxels = desc.extent.x * desc.extent.y * desc.extent.z;
  const std::uint64_t entries = desc.type == VoxelType::u8 ? 256u : 65536u;
  std::vector<std::vector<std::uint32_t>> luts(desc.channels);
  for (std::uint32_t c = 0; c < desc.channels && voxels >= entries; ++c) {
    luts[c] = occupancy_lut(desc.type, desc.range(c));
  }
  for_each_tile(desc, level0, tile_edge(pyramid.block_size()), threads,
                [&](const Box3& box, std::uint32_t c, std::span<const std::byte> v) {
                  tile_metadata(box, v, desc.type, desc.range(c), luts[c], c, pyramid);
                });
  pyramid.build();
}

}  // namespace resoct::detail
