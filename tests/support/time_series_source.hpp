#pragma once
// An in-memory time series for tests: one FunctionSource per timepoint over the same volume
// description, exposed through the BrickSource time-series interface (timepoints(),
// open_timepoint()). Reads of chosen timepoints can be held at a gate until released, so a test
// can switch timepoints while a load is provably in flight -- without sleeping.

#include <condition_variable>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "support/function_source.hpp"

namespace resoct::test {

/// Holds read_brick() of the gated timepoints until open(); counts reads that arrived.
class ReadGate {
 public:
  explicit ReadGate(std::set<std::uint32_t> gated) : gated_(std::move(gated)) {}
  /// Called by reads; blocks while the gate is shut and `timepoint` is gated.
  void pass(std::uint32_t timepoint);
  /// Blocks until `n` gated reads are waiting at the gate.
  void wait_for_waiting(std::size_t n);
  void open();

 private:
  std::set<std::uint32_t> gated_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
  std::size_t waiting_ = 0;
};

class TimeSeriesSource : public BrickSource {
 public:
  /// value(timepoint, channel, level-0 voxel) in voxel units.
  using SeriesFn = std::function<double(std::uint32_t timepoint, std::uint32_t channel,
                                        const glm::u64vec3& voxel)>;
  /// Timepoint `first` of a series of `timepoints`. `gate` may be null.
  TimeSeriesSource(VolumeDesc volume, BrickLayout layout, std::uint32_t timepoints, SeriesFn value,
                   std::uint32_t first = 0, std::shared_ptr<ReadGate> gate = nullptr);

  const BrickHierarchy& hierarchy() const override { return frames_->at(t_)->hierarchy(); }
  void read_brick(BrickKey key, std::span<std::byte> out) const override;
  RegionMeta region_meta(std::uint32_t channel, const Box3& level0_region) const override {
    return frames_->at(t_)->region_meta(channel, level0_region);
  }
  std::string name() const override { return "time-series"; }
  std::uint32_t timepoints() const override { return std::uint32_t(frames_->size()); }
  std::uint32_t timepoint() const override { return t_; }
  std::shared_ptr<const BrickSource> open_timepoint(std::uint32_t t) const override;

 private:
  using Frames = std::vector<std::shared_ptr<const FunctionSource>>;
  TimeSeriesSource(std::shared_ptr<const Frames> frames, std::uint32_t t,
                   std::shared_ptr<ReadGate> gate)
      : frames_(std::move(frames)), t_(t), gate_(std::move(gate)) {}

  std::shared_ptr<const Frames> frames_;
  std::uint32_t t_ = 0;
  std::shared_ptr<ReadGate> gate_;
};

/// 32³ u8, bricks 8³ + halo 1, `timepoints` timepoints: a ball whose centre moves along x with
/// the timepoint and whose values change with it, in an otherwise empty volume (so empty-space
/// skipping, brick metadata and region metadata all differ between timepoints).
std::shared_ptr<TimeSeriesSource> make_moving_ball_series(std::uint32_t timepoints,
                                                          std::uint32_t first = 0,
                                                          std::shared_ptr<ReadGate> gate = nullptr);

}  // namespace resoct::test
