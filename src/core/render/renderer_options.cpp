#include "resoct/render/renderer_options.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include "resoct/base/error.hpp"
#include "resoct/kernel/frame.glsl.h"

namespace resoct {

namespace {
// An enum field set by a cast from a bad integer (a binding, a config reader) must not reach the
// code that trusts it; every to_string() names invalid values "unknown".
template <typename E>
void check_choice(E value, std::string_view field) {
  if (std::string_view(to_string(value)) == "unknown") {
    throw invalid_parameter(field, "is not a valid choice");
  }
}
}  // namespace

std::uint32_t default_loader_threads() noexcept {
  return std::max(1u, std::thread::hardware_concurrency());
}

void ViewerOptions::validate() const {
  if (device_cache_bytes == 0) throw invalid_parameter("device_cache_bytes", "must be > 0");
  if (loader_threads > 1024) throw invalid_parameter("loader_threads", "must be at most 1024");
  if (retry_failed_after_ms > 3600000u) {
    throw invalid_parameter("retry_failed_after_ms", "must be at most 3600000 (one hour)");
  }
  check_choice(mode, "mode");
  check_choice(strategy, "strategy");
  check_choice(eviction, "eviction");
  check_choice(host_eviction, "host_eviction");
  check_choice(output, "output");
  if (prefetch.lookahead_frames > 64) {
    throw invalid_parameter("prefetch.lookahead_frames", "must be at most 64");
  }
  if ((prefetch.lookahead_frames > 0 || prefetch.next_timepoint) &&
      (prefetch.max_bricks == 0 || prefetch.max_bytes == 0)) {
    throw invalid_parameter("prefetch", "max_bricks and max_bytes must be > 0 when enabled");
  }
}

void TuningOptions::validate() const {
  if (visible_slots > kernel::RESOCT_MAX_SLOTS) {
    throw invalid_parameter("visible_slots", "must be at most RESOCT_MAX_SLOTS (32)");
  }
  if (upload_budget.max_bricks == 0 || upload_budget.max_bytes == 0) {
    throw invalid_parameter("upload_budget", "bricks and bytes per frame must be > 0");
  }
  if (ttl == 0) throw invalid_parameter("ttl", "must be >= 1");
  if (brick_request_capacity == 0 || brick_request_capacity > (1u << 28)) {
    throw invalid_parameter("brick_request_capacity", "must be 1..2^28");
  }
  if (node_request_capacity == 0 || node_request_capacity > (1u << 28)) {
    throw invalid_parameter("node_request_capacity", "must be 1..2^28");
  }
  if (max_node_answers == 0) throw invalid_parameter("max_node_answers", "must be > 0");
  if (max_iterations == 0) throw invalid_parameter("max_iterations", "must be > 0");
  if (!std::isfinite(skip_min_samples) || skip_min_samples < 0.0f) {
    throw invalid_parameter("skip_min_samples", "must be finite and >= 0");
  }
}

void RendererOptions::validate() const {
  if (backend.empty()) throw invalid_parameter("backend", "must not be empty");
  ViewerOptions::validate();
  TuningOptions::validate();
}

}  // namespace resoct
