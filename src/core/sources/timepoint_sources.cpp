#include "resoct/sources/timepoint_sources.hpp"

#include <algorithm>

#include "resoct/base/error.hpp"

namespace resoct {

TimepointSources::TimepointSources(std::shared_ptr<const BrickSource> series, std::uint32_t keep)
    : series_(std::move(series)), keep_(std::max(keep, 1u)) {
  if (!series_) throw invalid_parameter("source", "must not be null");
  count_ = std::max(series_->timepoints(), 1u);
}

std::shared_ptr<const BrickSource> TimepointSources::at(std::uint32_t t) {
  if (t == series_->timepoint()) return series_;
  std::lock_guard lock(mutex_);
  ++uses_;
  for (Opened& o : opened_) {
    if (o.timepoint == t) {
      o.last_use = uses_;
      return o.source;
    }
  }
  std::shared_ptr<const BrickSource> s = source_at_timepoint(series_, t);
  if (opened_.size() >= keep_) {
    // A source still in use elsewhere (a loader thread reading it) lives on through its
    // shared_ptr; dropping it here only ends the caching.
    const auto oldest =
        std::min_element(opened_.begin(), opened_.end(),
                         [](const Opened& a, const Opened& b) { return a.last_use < b.last_use; });
    opened_.erase(oldest);
  }
  opened_.push_back(Opened{t, s, uses_});
  return s;
}

}  // namespace resoct
