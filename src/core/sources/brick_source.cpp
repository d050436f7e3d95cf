#include "resoct/sources/brick_source.hpp"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "resoct/base/error.hpp"
#include "resoct/sources/brick_error.hpp"

namespace resoct {

namespace {
template <typename T>
BrickMeta scan_typed(std::span<const std::byte> bytes) {
  BrickMeta m;
  const std::size_t n = bytes.size() / sizeof(T);
  double first = 0.0;
  bool have_first = false;
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
    const double d = double(v);
    if (std::isnan(d)) continue;
    if (!have_first) {
      first = d;
      have_first = true;
    } else if (d != first) {
      m.constant = false;
    }
    m.min = d < m.min ? d : m.min;
    m.max = d > m.max ? d : m.max;
  }
  return m;
}
}  // namespace

BrickMeta scan_brick(std::span<const std::byte> voxels, VoxelType t) {
  switch (t) {
    case VoxelType::u8: return scan_typed<std::uint8_t>(voxels);
    case VoxelType::u16: return scan_typed<std::uint16_t>(voxels);
    case VoxelType::f32: return scan_typed<float>(voxels);
  }
  return {};
}

double BrickSource::brick_error(BrickKey key, std::span<const std::byte> padded) const {
  return measure_brick_error(*this, key, padded);
}

BrickMeta BrickSource::brick_meta(BrickKey key) const {
  const BrickLayout& layout = hierarchy().layout();
  std::vector<std::byte> buf(layout.padded_voxels() * voxel_size(volume().type));
  read_brick(key, buf);
  return scan_brick(buf, volume().type);
}

void BrickSource::check_brick_request(BrickKey key, std::span<const std::byte> out) const {
  if (!hierarchy().contains(key)) {
    const glm::uvec3 b = key.brick();
    throw Error(ErrorCode::out_of_range,
                name() + ": no brick (level " + std::to_string(key.level()) + ", channel " +
                    std::to_string(key.channel()) + ", brick " + std::to_string(b.x) + "," +
                    std::to_string(b.y) + "," + std::to_string(b.z) + ") in this hierarchy");
  }
  const std::size_t want = hierarchy().layout().padded_voxels() * voxel_size(volume().type);
  if (out.size() != want) {
    throw Error(ErrorCode::invalid_argument, name() + ": parameter 'out': brick buffer of " +
                                                 std::to_string(out.size()) + " bytes, expected " +
                                                 std::to_string(want));
  }
}

std::shared_ptr<const BrickSource> BrickSource::open_timepoint(std::uint32_t t) const {
  throw invalid_parameter("timepoint", std::to_string(t) + " but " + name() + " has " +
                                           std::to_string(timepoints()) + " timepoint(s)");
}

std::shared_ptr<const BrickSource> source_at_timepoint(std::shared_ptr<const BrickSource> source,
                                                       std::uint32_t t) {
  if (!source) throw invalid_parameter("source", "must not be null");
  const std::uint32_t n = source->timepoints();
  if (t >= n) {
    throw invalid_parameter("timepoint", std::to_string(t) + " but " + source->name() + " has " +
                                             std::to_string(n) + " timepoint(s) (0.." +
                                             std::to_string(n - 1) + ")");
  }
  if (t == source->timepoint()) return source;
  std::shared_ptr<const BrickSource> other = source->open_timepoint(t);
  if (!other || other->timepoint() != t || !(other->hierarchy() == source->hierarchy())) {
    throw Error(ErrorCode::corrupt, source->name() + ": timepoint " + std::to_string(t) +
                                        " has another volume description or brick layout than "
                                        "timepoint " +
                                        std::to_string(source->timepoint()));
  }
  return other;
}

}  // namespace resoct
