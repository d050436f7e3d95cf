#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/storage/checksum.hpp"
#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"
#include "resoct/sources/metadata_pyramid.hpp"
#include "resoct/io/store/format.hpp"
#include "resoct/sources/brick_error.hpp"

namespace resoct {

namespace {
using detail::IndexEntry;

// One brick after a worker is done with it.
struct EncodedBrick {
  IndexEntry entry;  // offset filled in when written
  std::vector<std::byte> payload;
  float error = 0.0f;  // BrickSource::brick_error, with StoreWriteOptions::brick_errors
  std::uint32_t level = 0;
  std::uint64_t slot = 0;  // channel * bricks_per_channel + linear index
};

// Jobs run coarsest level first (an overview loads from the front of the file), bricks in
// linear order, channels of one brick next to each other (they are usually loaded together).
class JobOrder {
 public:
  explicit JobOrder(const BrickHierarchy& h) : h_(h), channels_(h.volume().channels) {
    std::uint64_t start = 0;
    for (std::uint32_t l = h.level_count(); l-- > 0;) {
      starts_.push_back(start);
      start += h.level(l).brick_count * channels_;
    }
    total_ = start;
  }
  std::uint64_t total() const noexcept { return total_; }
  BrickKey key(std::uint64_t job) const {
    const auto it = std::upper_bound(starts_.begin(), starts_.end(), job) - 1;
    const std::uint32_t l = h_.level_count() - 1u - std::uint32_t(it - starts_.begin());
    const std::uint64_t r = job - *it;
    const BrickKey k =
        h_.key_from_linear(std::uint32_t(r % channels_), h_.level(l).first_brick + r / channels_);
    return k;
  }

 private:
  const BrickHierarchy& h_;
  std::uint32_t channels_;
  std::vector<std::uint64_t> starts_;
  std::uint64_t total_ = 0;
};

// True when every voxel has the same bit pattern as the first (NaN payloads included), so the
// brick can be stored as one value and reproduced exactly.
bool bitwise_constant(std::span<const std::byte> v, std::size_t vs, std::uint32_t& bits) {
  for (std::size_t i = vs; i < v.size(); i += vs) {
    if (std::memcmp(v.data() + i, v.data(), vs) != 0) return false;
  }
  bits = 0;
  for (std::size_t i = 0; i < vs; ++i) bits |= std::uint32_t(v[i]) << (8 * i);
  return true;
}

// Folds the core of a level-0 brick into the metadata blocks it overlaps. Scanning happens
// outside the lock; only the cheap merges are serialized (blocks may straddle bricks).
void add_level0_metadata(const BrickHierarchy& h, BrickKey key, std::span<const std::byte> padded,
                         MetadataPyramid& pyramid, std::mutex& lock) {
  const VoxelType type = h.volume().type;
  const std::size_t vs = voxel_size(type);
  const ValueRange range = h.volume().range(key.channel());
  const Box3 core = h.core_box(0, key.brick());
  const glm::i64vec3 pad(h.layout().padded_size());
  const glm::i64vec3 origin = glm::i64vec3(key.brick()) * glm::i64vec3(h.layout().brick_size) -
                              glm::i64vec3(h.layout().halo);
  const std::int64_t bs = pyramid.block_size();
  std::vector<std::byte> scratch;
  std::vector<std::pair<glm::u64vec3, RegionMeta>> found;
  for (std::int64_t bz = core.lo.z / bs; bz * bs < core.hi.z; ++bz) {
    for (std::int64_t by = core.lo.y / bs; by * bs < core.hi.y; ++by) {
      for (std::int64_t bx = core.lo.x / bs; bx * bs < core.hi.x; ++bx) {
        const Box3 block{glm::i64vec3(bx, by, bz) * bs, glm::i64vec3(bx + 1, by + 1, bz + 1) * bs};
        const Box3 r = intersect(core, block);
        const std::size_t row = std::size_t(r.size().x) * vs;
        scratch.resize(std::size_t(r.volume()) * vs);
        std::size_t at = 0;
        for (std::int64_t z = r.lo.z; z < r.hi.z; ++z) {
          for (std::int64_t y = r.lo.y; y < r.hi.y; ++y) {
            const glm::i64vec3 p = glm::i64vec3(r.lo.x, y, z) - origin;
            const std::size_t src = std::size_t((p.z * pad.y + p.y) * pad.x + p.x) * vs;
            std::memcpy(scratch.data() + at, padded.data() + src, row);
            at += row;
          }
        }
        found.emplace_back(glm::u64vec3(bx, by, bz), scan_region(scratch, type, range));
      }
    }
  }
  const std::lock_guard<std::mutex> g(lock);
  for (const auto& [b, m] : found) pyramid.merge_block(key.channel(), b, m);
}

// Reads and compresses bricks on worker threads; hands them to the caller in job order through
// a bounded window so that memory stays bounded however slow the disk is.
class Pipeline {
 public:
  Pipeline(const BrickSource& src, const StoreWriteOptions& opt, MetadataPyramid& pyramid,
           std::uint32_t threads)
      : src_(src),
        h_(src.hierarchy()),
        opt_(opt),
        pyramid_(pyramid),
        order_(h_),
        window_(std::max<std::uint64_t>(8, 4u * std::uint64_t(threads))) {
    ring_.resize(std::size_t(window_));
    try {
      for (std::uint32_t t = 0; t < threads; ++t) workers_.emplace_back([this] { work(); });
    } catch (...) {
      stop();  // joinable threads must not outlive a constructor that throws
      throw;
    }
  }
  ~Pipeline() { stop(); }

  std::uint64_t total() const noexcept { return order_.total(); }

  /// The next brick in job order; rethrows a worker's exception.
  EncodedBrick next() {
    std::unique_lock<std::mutex> lk(m_);
    auto& slot = ring_[std::size_t(taken_ % window_)];
    ready_.wait(lk, [&] { return error_ || slot.has_value(); });
    if (error_) std::rethrow_exception(error_);
    EncodedBrick b = std::move(*slot);
    slot.reset();
    ++taken_;
    space_.notify_all();
    return b;
  }

  void stop() {
    {
      const std::lock_guard<std::mutex> g(m_);
      stopping_ = true;
    }
    space_.notify_all();
    for (std::thread& t : workers_) {
      if (t.joinable()) t.join();
    }
  }

 private:
  /// A worker thread. Everything it does, the allocation of its brick buffer included, reports
  /// through error_: an exception escaping a std::thread calls std::terminate, which aborted
  /// resoct-convert (and left its temporary file behind) when that buffer did not fit in memory.
  void work() {
    try {
      work_jobs();
    } catch (...) {
      const std::lock_guard<std::mutex> g(m_);
      if (!error_) error_ = std::current_exception();
      ready_.notify_all();
      space_.notify_all();
    }
  }

  void work_jobs() {
    std::vector<std::byte> buf(h_.layout().padded_voxels() * voxel_size(h_.volume().type));
    for (;;) {
      std::uint64_t job = 0;
      {
        std::unique_lock<std::mutex> lk(m_);
        space_.wait(lk, [&] {
          return stopping_ || error_ || next_job_ >= total() || next_job_ < taken_ + window_;
        });
        if (stopping_ || error_ || next_job_ >= total()) return;
        job = next_job_++;
      }
      EncodedBrick b = encode(order_.key(job), buf);
      const std::lock_guard<std::mutex> g(m_);
      ring_[std::size_t(job % window_)] = std::move(b);
      ready_.notify_all();
    }
  }

  EncodedBrick encode(BrickKey key, std::vector<std::byte>& buf) const {
    src_.read_brick(key, buf);
    const VoxelType type = h_.volume().type;
    EncodedBrick b;
    b.level = key.level();
    b.slot = std::uint64_t(key.channel()) * h_.bricks_per_channel() +
             h_.linear_index(key.level(), key.brick());
    const BrickMeta meta = scan_brick(buf, type);
    b.entry.min = meta.min;
    b.entry.max = meta.max;
    b.entry.flags = meta.constant ? detail::kEntryConstant : 0u;
    if (key.level() == 0) add_level0_metadata(h_, key, buf, pyramid_, pyramid_lock_);
    if (opt_.brick_errors && key.level() > 0) {
      b.error = brick_error_to_float(src_.brick_error(key, buf));
    }
    std::uint32_t bits = 0;
    if (bitwise_constant(buf, voxel_size(type), bits)) {
      b.entry.fill_bits = bits;
      return b;
    }
    b.payload = compress(opt_.codec, opt_.level, buf);
    if (b.payload.size() > std::numeric_limits<std::uint32_t>::max()) {
      throw Error(ErrorCode::unsupported, src_.name() + ": a compressed brick exceeds 4 GiB");
    }
    b.entry.flags |= detail::kEntryStored;
    b.entry.size = std::uint32_t(b.payload.size());
    b.entry.crc = crc32(b.payload);
    return b;
  }

  const BrickSource& src_;
  const BrickHierarchy& h_;
  const StoreWriteOptions& opt_;
  MetadataPyramid& pyramid_;
  mutable std::mutex pyramid_lock_;
  JobOrder order_;
  std::uint64_t window_;

  std::mutex m_;
  std::condition_variable ready_;  // a slot was filled or a worker failed
  std::condition_variable space_;  // the window moved, or stop
  std::vector<std::optional<EncodedBrick>> ring_;
  std::uint64_t next_job_ = 0;
  std::uint64_t taken_ = 0;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> workers_;
};

std::vector<StoreLevelStats> empty_level_stats(const BrickHierarchy& h) {
  std::vector<StoreLevelStats> out(h.level_count());
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    out[l].extent = h.level(l).extent;
    out[l].bricks = h.level(l).bricks;
  }
  return out;
}
}  // namespace

StoreSummary write_brick_store(const BrickSource& src, const std::string& path,
                               const StoreWriteOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const BrickHierarchy& h = src.hierarchy();
  const VolumeDesc& vol = h.volume();
  validate_codec_level(options.codec, options.level);
  const std::uint64_t brick_bytes = h.layout().padded_voxels() * voxel_size(vol.type);
  compress_bound(options.codec, std::size_t(brick_bytes));  // rejects bricks too big for LZ4
  MetadataPyramid pyramid(vol.extent, options.metadata_block, vol.channels);
  std::uint32_t threads = options.threads;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = std::min(threads, 256u);

  detail::StoreHeader hdr;
  hdr.volume = vol;
  hdr.layout = h.layout();
  hdr.flags = vol.ranges.empty() ? detail::kFlagDefaultRanges : 0u;
  if (vol.origin != glm::dvec3(0.0)) hdr.flags |= detail::kFlagOrigin;
  if (options.brick_errors) hdr.flags |= detail::kFlagBrickErrors;
  hdr.codec = options.codec;
  hdr.codec_level = options.level;
  hdr.metadata_block = options.metadata_block;
  hdr.level_count = h.level_count();
  hdr.bricks_per_channel = h.bricks_per_channel();
  const std::uint64_t header_size = detail::header_size_for(vol.channels, hdr.flags);

  AtomicFileWriter out(path);
  out.append(std::vector<std::byte>(header_size));  // rewritten once the offsets are known
  hdr.payload_offset = out.position();

  StoreSummary summary;
  summary.stats.levels = empty_level_stats(h);
  std::vector<detail::IndexEntry> index(std::size_t(h.bricks_per_channel() * vol.channels));
  std::vector<float> errors(options.brick_errors ? index.size() : 0);
  {
    Pipeline pipe(src, options, pyramid, threads);
    const std::uint64_t total = pipe.total();
    for (std::uint64_t done = 0; done < total;) {
      EncodedBrick b = pipe.next();
      StoreLevelStats& ls = summary.stats.levels[b.level];
      ls.brick_count += 1;
      ls.uncompressed_bytes += brick_bytes;
      if ((b.entry.flags & detail::kEntryStored) != 0) {
        b.entry.offset = out.position();
        out.append(b.payload);
        ls.compressed_bytes += b.payload.size();
      } else {
        ls.constant_bricks += 1;
      }
      if ((b.entry.flags & detail::kEntryConstant) != 0 && b.entry.min == 0.0 &&
          b.entry.max == 0.0) {
        ls.empty_bricks += 1;
      }
      index[std::size_t(b.slot)] = b.entry;
      if (!errors.empty()) {
        errors[std::size_t(b.slot)] = b.error;
        ls.max_error = std::max(ls.max_error, double(b.error));
        ls.mean_error += double(b.error);
      }
      ++done;
      if (options.progress) options.progress(done, total);
    }
  }
  hdr.payload_size = out.position() - hdr.payload_offset;

  std::vector<std::byte> index_bytes(index.size() * detail::kIndexEntrySize);
  for (std::size_t i = 0; i < index.size(); ++i) {
    detail::encode_index_entry(
        index[i], std::span<std::byte, detail::kIndexEntrySize>(
                      index_bytes.data() + i * detail::kIndexEntrySize, detail::kIndexEntrySize));
  }
  hdr.index_offset = out.position();
  hdr.index_size = index_bytes.size();
  hdr.index_crc = crc32(index_bytes);
  out.append(index_bytes);

  pyramid.build();
  const std::vector<std::byte> raw_meta = detail::encode_metadata(pyramid);
  const std::vector<std::byte> meta = compress(Codec::zstd, 0, raw_meta);
  hdr.metadata_offset = out.position();
  hdr.metadata_size = meta.size();
  hdr.metadata_raw_size = raw_meta.size();
  hdr.metadata_crc = crc32(meta);
  out.append(meta);

  if (!errors.empty()) {
    const std::vector<std::byte> packed = compress(Codec::zstd, 0, detail::encode_errors(errors));
    hdr.errors_offset = out.position();
    hdr.errors_size = packed.size();
    hdr.errors_crc = crc32(packed);
    out.append(packed);
    summary.stats.brick_errors = true;
    for (StoreLevelStats& ls : summary.stats.levels) {
      if (ls.brick_count != 0) ls.mean_error /= double(ls.brick_count);
    }
  }

  out.write_at(0, detail::encode_header(hdr));
  summary.stats.codec = options.codec;
  summary.stats.codec_level = options.level;
  summary.stats.format_version = detail::kStoreVersion;
  summary.stats.file_bytes = out.position();
  out.commit();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace resoct
