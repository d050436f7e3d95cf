#include "support/time_series_source.hpp"

#include <cmath>

#include "resoct/base/error.hpp"

namespace resoct::test {

void ReadGate::pass(std::uint32_t timepoint) {
  if (!gated_.count(timepoint)) return;
  std::unique_lock lock(mutex_);
  ++waiting_;
  cv_.notify_all();
  cv_.wait(lock, [this] { return open_; });
  --waiting_;
}

void ReadGate::wait_for_waiting(std::size_t n) {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return waiting_ >= n; });
}

void ReadGate::open() {
  {
    std::lock_guard lock(mutex_);
    open_ = true;
  }
  cv_.notify_all();
}

TimeSeriesSource::TimeSeriesSource(VolumeDesc volume, BrickLayout layout, std::uint32_t timepoints,
                                   SeriesFn value, std::uint32_t first,
                                   std::shared_ptr<ReadGate> gate)
    : t_(first), gate_(std::move(gate)) {
  auto frames = std::make_shared<Frames>();
  for (std::uint32_t t = 0; t < timepoints; ++t) {
    frames->push_back(std::make_shared<FunctionSource>(
        volume, layout,
        [value, t](std::uint32_t c, const glm::u64vec3& p) { return value(t, c, p); },
        "time-series"));
  }
  frames_ = std::move(frames);
  if (t_ >= frames_->size()) throw invalid_parameter("timepoint", "past the series");
}

void TimeSeriesSource::read_brick(BrickKey key, std::span<std::byte> out) const {
  if (gate_) gate_->pass(t_);
  frames_->at(t_)->read_brick(key, out);
}

std::shared_ptr<const BrickSource> TimeSeriesSource::open_timepoint(std::uint32_t t) const {
  if (t >= frames_->size()) throw invalid_parameter("timepoint", "past the series");
  return std::shared_ptr<const BrickSource>(new TimeSeriesSource(frames_, t, gate_));
}

std::shared_ptr<TimeSeriesSource> make_moving_ball_series(std::uint32_t timepoints,
                                                          std::uint32_t first,
                                                          std::shared_ptr<ReadGate> gate) {
  VolumeDesc v;
  v.extent = {32, 32, 32};
  v.type = VoxelType::u8;
  v.channels = 1;
  return std::make_shared<TimeSeriesSource>(
      v, BrickLayout{glm::uvec3(8), 1}, timepoints,
      [](std::uint32_t t, std::uint32_t, const glm::u64vec3& p) {
        const glm::dvec3 centre(8.0 + 4.0 * t, 16.0, 16.0);
        const glm::dvec3 d = glm::dvec3(p) + 0.5 - centre;
        const double r = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        if (r > 7.0) return 0.0;
        return double(40 + 30 * t + (p.x * 3 + p.y * 5 + p.z * 7) % 50);
      },
      first, std::move(gate));
}

}  // namespace resoct::test
