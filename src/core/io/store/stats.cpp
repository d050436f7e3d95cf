#include <algorithm>
#include <limits>

#include "resoct/io/store/brick_store.hpp"

namespace resoct {

double StoreLevelStats::compression_ratio() const noexcept {
  if (compressed_bytes == 0) return std::numeric_limits<double>::infinity();
  return double(uncompressed_bytes) / double(compressed_bytes);
}

double StoreLevelStats::empty_fraction() const noexcept {
  return brick_count == 0 ? 0.0 : double(empty_bricks) / double(brick_count);
}

StoreLevelStats StoreStats::total() const noexcept {
  StoreLevelStats t;
  for (const StoreLevelStats& l : levels) {
    t.brick_count += l.brick_count;
    t.constant_bricks += l.constant_bricks;
    t.empty_bricks += l.empty_bricks;
    t.compressed_bytes += l.compressed_bytes;
    t.uncompressed_bytes += l.uncompressed_bytes;
    t.max_error = std::max(t.max_error, l.max_error);
    t.mean_error += l.mean_error * double(l.brick_count);
  }
  if (t.brick_count != 0) t.mean_error /= double(t.brick_count);
  if (!levels.empty()) {
    t.extent = levels.front().extent;
    t.bricks = levels.front().bricks;
  }
  return t;
}

}  // namespace resoct
