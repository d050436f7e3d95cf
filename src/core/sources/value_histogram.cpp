#include "resoct/sources/value_histogram.hpp"

#include <cmath>
#include <cstring>
#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

std::vector<std::uint64_t> coarse_value_histogram(const BrickSource& source, std::uint32_t channel,
                                                  std::uint32_t bins) {
  const BrickHierarchy& h = source.hierarchy();
  const VolumeDesc& volume = h.volume();
  if (channel >= volume.channels) {
    throw invalid_parameter("channel", std::to_string(channel) + " is past the volume's " +
                                           std::to_string(volume.channels) + " channels");
  }
  if (bins == 0 || bins > (1u << 20)) throw invalid_parameter("bins", "must be 1..2^20");
  const ValueRange range = volume.range(channel);
  const double width = range.hi - range.lo;
  const double scale = width > 0.0 ? double(bins) / width : 0.0;
  std::vector<std::uint64_t> counts(bins, 0);
  const std::uint32_t level = h.level_count() - 1;
  const LevelInfo& info = h.level(level);
  const BrickLayout& layout = h.layout();
  const glm::uvec3 padded = layout.padded_size();
  const std::size_t vbytes = voxel_size(volume.type);
  std::vector<std::byte> brick(layout.padded_voxels() * vbytes);
  for (std::uint32_t z = 0; z < info.bricks.z; ++z) {
    for (std::uint32_t y = 0; y < info.bricks.y; ++y) {
      for (std::uint32_t x = 0; x < info.bricks.x; ++x) {
        const glm::uvec3 b(x, y, z);
        source.read_brick(BrickKey(level, channel, b), brick);
        // Core voxels only, clipped to the level (a border brick's core reaches past it): each
        // voxel of the level is counted once.
        const Box3 core = h.core_box(level, b);
        const glm::i64vec3 n = glm::min(core.hi, glm::i64vec3(info.extent)) - core.lo;
        for (std::int64_t k = 0; k < n.z; ++k) {
          for (std::int64_t j = 0; j < n.y; ++j) {
            for (std::int64_t i = 0; i < n.x; ++i) {
              const std::size_t idx =
                  (std::size_t(k + layout.halo) * padded.y + std::size_t(j + layout.halo)) *
                      padded.x +
                  std::size_t(i + layout.halo);
              const double v = voxel_value(brick.data() + idx * vbytes, volume.type);
              if (std::isnan(v)) continue;
              const double pos = (v - range.lo) * scale;
              const std::uint32_t bin = pos <= 0.0            ? 0u
                                        : pos >= double(bins) ? bins - 1u
                                                              : std::uint32_t(pos);
              ++counts[bin];
            }
          }
        }
      }
    }
  }
  return counts;
}

}  // namespace resoct
