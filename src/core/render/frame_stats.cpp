#include "resoct/render/frame_stats.hpp"

#include <cstdio>

namespace resoct {

double per_ray(std::uint64_t total, const BackendStats& stats) noexcept {
  return stats.rays == 0 ? 0.0 : double(total) / double(stats.rays);
}

std::string format_frame_line(const FrameStats& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "frame %llu: %llu brick requests, %llu node requests, %llu uploaded, "
                "%llu empty/homogeneous, %llu deferred, %llu queued, %.2f ms render, "
                "%.2f ms frame",
                static_cast<unsigned long long>(s.frame_index),
                static_cast<unsigned long long>(s.brick_requests),
                static_cast<unsigned long long>(s.node_requests),
                static_cast<unsigned long long>(s.bricks_uploaded),
                static_cast<unsigned long long>(s.pages_empty + s.pages_homogeneous),
                static_cast<unsigned long long>(s.uploads_deferred),
                static_cast<unsigned long long>(s.loads_queued + s.loads_in_flight), s.ms_render,
                s.ms_frame);
  return buf;
}

}  // namespace resoct
