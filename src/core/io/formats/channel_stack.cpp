#include <cmath>
#include <sstream>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/io/formats/channel_stack.hpp"

namespace resoct {

namespace {

std::string vec3_text(const glm::dvec3& v) {
  std::ostringstream o;
  o << '(' << v.x << ", " << v.y << ", " << v.z << ')';
  return o.str();
}

VolumeDesc stacked_desc(const std::vector<std::shared_ptr<const BrickSource>>& sources) {
  if (sources.empty()) throw invalid_parameter("sources", "no source to stack");
  const BrickSource& first = *sources.front();
  VolumeDesc d = first.volume();
  d.channels = 0;
  d.ranges.clear();
  for (const auto& s : sources) {
    const VolumeDesc& v = s->volume();
    // One value offset for the whole volume: an i16 channel cannot sit beside a u16 one.
    if (v.extent != first.volume().extent || v.file_type() != first.volume().file_type() ||
        !(s->hierarchy().layout() == first.hierarchy().layout())) {
      throw invalid_parameter("sources", "'" + s->name() + "' differs from '" + first.name() +
                                             "' in extent, value type or brick layout");
    }
    // Channels share one voxel grid in space too: a file placed elsewhere (another origin or
    // voxel size, after each reader's reordering to world axes) is not silently overlaid.
    // Tolerance: a thousandth of a voxel, for headers that store the same grid in float.
    const VolumeDesc& f = first.volume();
    for (int a = 0; a < 3; ++a) {
      const double tol = 1e-3 * f.spacing[a];
      if (std::fabs(v.spacing[a] - f.spacing[a]) > tol ||
          std::fabs(v.origin[a] - f.origin[a]) > tol) {
        throw invalid_parameter("sources", "'" + s->name() + "' is not on the grid of '" +
                                               first.name() + "': spacing " + vec3_text(v.spacing) +
                                               " vs " + vec3_text(f.spacing) + ", origin " +
                                               vec3_text(v.origin) + " vs " + vec3_text(f.origin));
      }
    }
    if (d.channels + v.channels > kMaxChannels) {
      throw invalid_parameter("sources", "more than " + std::to_string(kMaxChannels) + " channels");
    }
    for (std::uint32_t c = 0; c < v.channels; ++c) d.ranges.push_back(v.range(c));
    d.channels += v.channels;
  }
  return d;
}

class ChannelStack final : public BrickSource {
 public:
  ChannelStack(std::vector<std::shared_ptr<const BrickSource>> sources, std::string name)
      : hierarchy_(stacked_desc(sources), sources.front()->hierarchy().layout()),
        sources_(std::move(sources)),
        name_(std::move(name)) {
    for (std::size_t i = 0; i < sources_.size(); ++i) {
      for (std::uint32_t c = 0; c < sources_[i]->volume().channels; ++c) owner_.push_back({i, c});
    }
  }

  const BrickHierarchy& hierarchy() const override { return hierarchy_; }
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    check_brick_request(key, out);
    const auto [i, c] = owner_[key.channel()];
    sources_[i]->read_brick(BrickKey(key.level(), c, key.brick()), out);
  }
  BrickMeta brick_meta(BrickKey key) const override {
    if (!hierarchy_.contains(key)) {
      throw Error(ErrorCode::out_of_range, name_ + ": brick key not in the hierarchy");
    }
    const auto [i, c] = owner_[key.channel()];
    return sources_[i]->brick_meta(BrickKey(key.level(), c, key.brick()));
  }
  // The member source's own answer (stored or cached there); the stack keeps its value ranges.
  double brick_error(BrickKey key, std::span<const std::byte> padded) const override {
    check_brick_request(key, padded);
    const auto [i, c] = owner_[key.channel()];
    return sources_[i]->brick_error(BrickKey(key.level(), c, key.brick()), padded);
  }
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override {
    if (channel >= owner_.size()) {
      throw Error(ErrorCode::out_of_range, name_ +
                                               ": parameter 'channel': " + std::to_string(channel) +
                                               " of " + std::to_string(owner_.size()));
    }
    const auto [i, c] = owner_[channel];
    return sources_[i]->region_meta(c, level0_region);
  }
  std::string name() const override { return name_; }

 private:
  struct Owner {
    std::size_t source;
    std::uint32_t channel;
  };
  BrickHierarchy hierarchy_;
  std::vector<std::shared_ptr<const BrickSource>> sources_;
  std::string name_;
  std::vector<Owner> owner_;
};

}  // namespace

std::unique_ptr<BrickSource> stack_channels(std::vector<std::shared_ptr<const BrickSource>> sources,
                                            std::string name) {
  return std::make_unique<ChannelStack>(std::move(sources), std::move(name));
}

}  // namespace resoct
