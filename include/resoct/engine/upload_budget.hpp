#pragma once
/// \file
/// The per-frame upload limits (RendererOptions::upload_budget), apart from the device cache
/// that applies them (brick_cache.hpp: plan_uploads).

#include <cstdint>
#include <limits>

namespace resoct {

/// Per-frame upload limits (paper 001's reload limit), in bricks and in bytes.
struct UploadBudget {
  std::uint64_t max_bricks = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t max_bytes = std::numeric_limits<std::uint64_t>::max();
};

}  // namespace resoct
