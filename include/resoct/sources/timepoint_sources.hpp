#pragma once
/// \file
/// The sources of the timepoints of one series, opened on first use and shared between the
/// renderer (region metadata of the current timepoint) and the loader threads (bricks of the
/// current and the next timepoint).

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// Keeps the series' own source and the last `keep` other timepoints opened (least recently
/// used dropped first): a timepoint source may own caches (decoded chunks, computed levels,
/// metadata) that should not accumulate over a long series, while playing needs the current and
/// the next one. Thread-safety: every member may be called from any thread; at() opens under
/// the lock, so two threads never open the same timepoint twice.
class TimepointSources {
 public:
  /// Throws Error(invalid_argument) naming "source" when it is null.
  explicit TimepointSources(std::shared_ptr<const BrickSource> series, std::uint32_t keep = 3);

  /// The series' source as given (it reads series().timepoint()).
  const std::shared_ptr<const BrickSource>& series() const noexcept { return series_; }
  std::uint32_t count() const noexcept { return count_; }
  /// The source of timepoint t (source_at_timepoint, cached). Throws as that does.
  std::shared_ptr<const BrickSource> at(std::uint32_t t);

 private:
  struct Opened {
    std::uint32_t timepoint = 0;
    std::shared_ptr<const BrickSource> source;
    std::uint64_t last_use = 0;
  };

  std::shared_ptr<const BrickSource> series_;
  std::uint32_t count_ = 1;
  std::uint32_t keep_ = 3;
  std::mutex mutex_;
  std::vector<Opened> opened_;
  std::uint64_t uses_ = 0;
};

}  // namespace resoct
