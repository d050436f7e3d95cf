#include "resoct/io/formats/pyramid_source.hpp"

#include <cmath>
#include <cstring>
#include <string>

#include "io/formats/brick_error_cache.hpp"
#include "io/formats/lazy_metadata.hpp"
#include "io/formats/level0_scan.hpp"
#include "resoct/volume/downsample.hpp"
#include "resoct/base/error.hpp"
#include "resoct/sources/brick_error.hpp"

namespace resoct {

namespace {

VolumeDesc checked(VolumeDesc desc, const std::vector<LevelBoxReader>& levels,
                   const PyramidSourceOptions& o) {
  desc.validate();
  if (levels.empty() || !levels[0]) throw invalid_parameter("levels", "no level-0 reader");
  const std::uint32_t b = o.metadata_block;
  if (b < 4 || b > 1024 || (b & (b - 1)) != 0) {
    throw invalid_parameter("metadata_block", "must be a power of two in 4..1024");
  }
  if (o.lazy_query_blocks == 0) throw invalid_parameter("lazy_query_blocks", "must be > 0");
  if (o.lazy_cache_entries == 0) throw invalid_parameter("lazy_cache_entries", "must be > 0");
  if (o.error_cache_entries == 0) throw invalid_parameter("error_cache_entries", "must be > 0");
  return desc;
}

/// Copies `region` (inside both boxes) from a dense buffer of `src_box` into one of `dst_box`.
void copy_region(std::span<const std::byte> src, const Box3& src_box, std::span<std::byte> dst,
                 const Box3& dst_box, const Box3& region, std::size_t vs) {
  const glm::i64vec3 ss = src_box.size(), ds = dst_box.size(), rs = region.size();
  const std::size_t run = std::size_t(rs.x) * vs;
  for (std::int64_t z = region.lo.z; z < region.hi.z; ++z) {
    for (std::int64_t y = region.lo.y; y < region.hi.y; ++y) {
      const std::size_t s = std::size_t(((z - src_box.lo.z) * ss.y + (y - src_box.lo.y)) * ss.x +
                                        (region.lo.x - src_box.lo.x)) *
                            vs;
      const std::size_t d = std::size_t(((z - dst_box.lo.z) * ds.y + (y - dst_box.lo.y)) * ds.x +
                                        (region.lo.x - dst_box.lo.x)) *
                            vs;
      std::memcpy(dst.data() + d, src.data() + s, run);
    }
  }
}

}  // namespace

ValueRange data_value_range(double finite_min, double finite_max) noexcept {
  if (!(finite_min <= finite_max)) return ValueRange{0.0, 1.0};
  if (finite_min == finite_max) return ValueRange{finite_min, finite_min + 1.0};
  return ValueRange{finite_min, finite_max};
}

PyramidSource::PyramidSource(VolumeDesc desc, BrickLayout layout,
                             std::vector<LevelBoxReader> levels, std::string name,
                             PyramidSourceOptions options)
    : hierarchy_(checked(std::move(desc), levels, options), layout),
      levels_(std::move(levels)),
      name_(std::move(name)),
      cache_(std::make_unique<HostBrickCache>(options.cache_bytes)),
      errors_(std::make_unique<detail::BrickErrorCache>(options.error_cache_entries)),
      timepoints_(options.timepoints),
      timepoint_(options.timepoint),
      open_timepoint_(std::move(options.open_timepoint)) {
  VolumeDesc d = hierarchy_.volume();
  const std::uint64_t voxels0 = d.voxel_count();
  const bool eager = voxels0 <= options.eager_scan_voxels / d.channels;
  if (options.ranges_from_data) {
    // Lazily: the coarsest stored level that fits the eager budget estimates the ranges (its
    // averaged voxels may miss thin extremes, which only coarsens the occupancy bins; the
    // block summaries themselves stay exact).
    std::uint32_t scan_level = 0;
    bool scan = eager;
    for (std::uint32_t l = hierarchy_.level_count(); !scan && l-- > 1;) {
      const glm::u64vec3 e = hierarchy_.level(l).extent;
      if (stored_level(l) && e.x * e.y * e.z <= options.eager_scan_voxels / d.channels) {
        scan_level = l;
        scan = true;
      }
    }
    if (scan) {
      VolumeDesc level_desc = d;
      level_desc.extent = hierarchy_.level(scan_level).extent;
      const auto mm = detail::scan_finite_minmax(level_desc, levels_[scan_level], options.threads);
      d.ranges.clear();
      for (const auto& [lo, hi] : mm) d.ranges.push_back(data_value_range(lo, hi));
      hierarchy_ = BrickHierarchy(d, layout);
    }
  }
  if (eager) {
    pyramid_ = MetadataPyramid(d.extent, options.metadata_block, d.channels);
    detail::fill_metadata(d, levels_[0], pyramid_, options.threads);
  } else {
    lazy_ = std::make_unique<detail::LazyMetadata>(d, levels_[0], options.metadata_block,
                                                   options.lazy_query_blocks,
                                                   options.lazy_cache_entries);
  }
}

std::shared_ptr<const BrickSource> PyramidSource::open_timepoint(std::uint32_t t) const {
  if (!open_timepoint_) return BrickSource::open_timepoint(t);
  return open_timepoint_(t, *this);
}

PyramidSource::~PyramidSource() = default;

std::uint64_t PyramidSource::lazy_blocks_computed() const noexcept {
  return lazy_ ? lazy_->blocks_computed() : 0;
}

std::uint64_t PyramidSource::brick_errors_measured() const noexcept {
  return errors_->measured();
}

double PyramidSource::brick_error(BrickKey key, std::span<const std::byte> padded) const {
  check_brick_request(key, padded);
  if (key.level() == 0) return 0.0;
  return errors_->get(key, [&] { return measure_brick_error(*this, key, padded); });
}

bool PyramidSource::stored_level(std::uint32_t level) const noexcept {
  return level < levels_.size() && bool(levels_[level]);
}

std::shared_ptr<const HostBrick> PyramidSource::computed_core(std::uint32_t level,
                                                              std::uint32_t channel,
                                                              const glm::uvec3& brick) const {
  const BrickKey key(level, channel, brick);
  if (auto hit = cache_->get(key)) return hit;
  const LevelInfo& fine = hierarchy_.level(level - 1);
  const glm::bvec3 halve = glm::greaterThan(hierarchy_.level(level).factor_log2, fine.factor_log2);
  const Box3 core = hierarchy_.core_box(level, brick);
  auto tile = std::make_shared<HostBrick>();
  tile->key = key;
  // Never "constant": HostBrick drops the voxels of constant bricks, and these are reused.
  tile->meta.constant = false;
  tile->voxels.resize(std::size_t(core.volume()) * voxel_size(volume().type));
  downsample_region(
      core, fine.extent, halve, volume().type,
      [&](const Box3& fine_box, std::span<std::byte> out) {
        read_level_box(level - 1, channel, fine_box, out);
      },
      tile->voxels);
  cache_->put(tile);
  return tile;
}

void PyramidSource::read_level_box(std::uint32_t level, std::uint32_t channel, const Box3& box,
                                   std::span<std::byte> out) const {
  if (level >= hierarchy_.level_count() || channel >= volume().channels) {
    throw invalid_parameter("level", name_ + ": no level " + std::to_string(level) + " channel " +
                                         std::to_string(channel));
  }
  const LevelInfo& info = hierarchy_.level(level);
  const Box3 whole{glm::i64vec3(0), glm::i64vec3(info.extent)};
  const std::size_t vs = voxel_size(volume().type);
  if (box.empty() || intersect(box, whole) != box) {
    throw invalid_parameter("box", name_ + ": box outside level " + std::to_string(level));
  }
  if (out.size() != std::size_t(box.volume()) * vs) {
    throw invalid_parameter("out", "buffer of " + std::to_string(out.size()) +
                                       " bytes for a box of " + std::to_string(box.volume()) +
                                       " voxels");
  }
  if (stored_level(level)) {
    levels_[level](channel, box, out);
    return;
  }
  const glm::i64vec3 bs(hierarchy_.layout().brick_size);
  const glm::i64vec3 b0 = box.lo / bs, b1 = (box.hi - std::int64_t(1)) / bs;
  for (std::int64_t z = b0.z; z <= b1.z; ++z) {
    for (std::int64_t y = b0.y; y <= b1.y; ++y) {
      for (std::int64_t x = b0.x; x <= b1.x; ++x) {
        const glm::uvec3 b(glm::i64vec3(x, y, z));
        const auto tile = computed_core(level, channel, b);
        const Box3 core = hierarchy_.core_box(level, b);
        copy_region(tile->voxels, core, out, box, intersect(core, box), vs);
      }
    }
  }
}

void PyramidSource::read_brick(BrickKey key, std::span<std::byte> out) const {
  check_brick_request(key, out);
  const std::uint32_t l = key.level();
  const Box3 padded = hierarchy_.padded_box(l, key.brick());
  const Box3 inner =
      intersect(padded, Box3{glm::i64vec3(0), glm::i64vec3(hierarchy_.level(l).extent)});
  if (inner == padded) {
    read_level_box(l, key.channel(), padded, out);
    return;
  }
  const std::size_t vs = voxel_size(volume().type);
  std::vector<std::byte> tmp(std::size_t(inner.volume()) * vs);
  read_level_box(l, key.channel(), inner, tmp);
  copy_box_clamped(tmp, inner, out, padded, vs);
}

RegionMeta PyramidSource::region_meta(std::uint32_t channel, const Box3& level0_region) const {
  if (channel >= volume().channels) {
    throw Error(ErrorCode::out_of_range, name_ +
                                             ": parameter 'channel': " + std::to_string(channel) +
                                             " of " + std::to_string(volume().channels));
  }
  return lazy_ ? lazy_->query(channel, level0_region) : pyramid_.query(channel, level0_region);
}

std::unique_ptr<PyramidSource> make_dense_pyramid_source(DenseVolume volume, BrickLayout layout,
                                                         std::string name,
                                                         PyramidSourceOptions options) {
  if (volume.bytes().empty()) throw invalid_parameter("volume", "empty DenseVolume");
  const VolumeDesc desc = volume.desc();
  const Box3 whole{glm::i64vec3(0), glm::i64vec3(desc.extent)};
  const std::size_t vs = voxel_size(desc.type);
  auto shared = std::make_shared<const DenseVolume>(std::move(volume));
  LevelBoxReader level0 = [shared, whole, vs](std::uint32_t c, const Box3& box,
                                              std::span<std::byte> out) {
    copy_box_clamped(shared->channel_bytes(c), whole, out, box, vs);
  };
  return std::make_unique<PyramidSource>(desc, layout, std::vector<LevelBoxReader>{level0},
                                         std::move(name), options);
}

}  // namespace resoct
