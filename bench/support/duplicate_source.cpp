#include "support/duplicate_source.hpp"

#include "resoct/base/error.hpp"

namespace resoct::bench {

namespace {
VolumeDesc duplicated(const BrickSource& base, std::uint32_t base_channel, std::uint32_t copies) {
  if (copies == 0 || copies > kMaxChannels) {
    throw invalid_parameter("copies", "must be in 1.." + std::to_string(kMaxChannels));
  }
  const VolumeDesc& v = base.volume();
  if (base_channel >= v.channels) {
    throw invalid_parameter("base_channel",
                            "the base source has " + std::to_string(v.channels) + " channels");
  }
  VolumeDesc out = v;
  out.channels = copies;
  out.ranges.assign(copies, v.range(base_channel));
  return out;
}
}  // namespace

DuplicateChannelSource::DuplicateChannelSource(std::shared_ptr<const BrickSource> base,
                                               std::uint32_t base_channel, std::uint32_t copies)
    : base_(std::move(base)),
      base_channel_(base_channel),
      hierarchy_(duplicated(*base_, base_channel, copies), base_->hierarchy().layout()) {}

BrickKey DuplicateChannelSource::base_key(BrickKey key) const {
  if (key.channel() >= hierarchy_.volume().channels) {
    throw Error(ErrorCode::out_of_range, name() + ": channel " + std::to_string(key.channel()) +
                                             " is not one of the duplicated channels");
  }
  return BrickKey(key.level(), base_channel_, key.brick());
}

void DuplicateChannelSource::read_brick(BrickKey key, std::span<std::byte> out) const {
  base_->read_brick(base_key(key), out);
}

BrickMeta DuplicateChannelSource::brick_meta(BrickKey key) const {
  return base_->brick_meta(base_key(key));
}

RegionMeta DuplicateChannelSource::region_meta(std::uint32_t channel,
                                               const Box3& level0_region) const {
  base_key(BrickKey(0, channel, glm::uvec3(0)));  // validates the channel
  return base_->region_meta(base_channel_, level0_region);
}

std::string DuplicateChannelSource::name() const {
  return base_->name() + " (channel " + std::to_string(base_channel_) + " x" +
         std::to_string(hierarchy_.volume().channels) + ")";
}

}  // namespace resoct::bench
