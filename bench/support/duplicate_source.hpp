#pragma once
// Paper 000 §8 / thesis §9 protocol for multi-channel rows of single-channel datasets: the
// volume is duplicated n times and each copy is rendered with its own transfer function. This
// source presents one channel of another source as `copies` identical channels (all brick,
// metadata and region queries forward to the base channel), so the renderer treats them as
// distinct channels (own slots, own cache bricks, own octree masks) holding the same data.
#include <cstdint>
#include <memory>
#include <string>

#include "resoct/sources/brick_source.hpp"

namespace resoct::bench {

/// Thread-safe when the base source is (every BrickSource is).
class DuplicateChannelSource : public BrickSource {
 public:
  /// Throws Error(invalid_argument) naming "copies" (0 or above kMaxChannels) or
  /// "base_channel" (not a channel of `base`).
  DuplicateChannelSource(std::shared_ptr<const BrickSource> base, std::uint32_t base_channel,
                         std::uint32_t copies);

  const BrickHierarchy& hierarchy() const override { return hierarchy_; }
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  BrickMeta brick_meta(BrickKey key) const override;
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override;
  std::string name() const override;

  const BrickSource& base() const noexcept { return *base_; }

 private:
  BrickKey base_key(BrickKey key) const;

  std::shared_ptr<const BrickSource> base_;
  std::uint32_t base_channel_;
  BrickHierarchy hierarchy_;
};

}  // namespace resoct::bench
