#pragma once
/// \file
/// The choice of eviction policy (RendererOptions::eviction, ::host_eviction) and its names,
/// apart from the policies themselves (eviction_policy.hpp), so that the renderer's options name
/// it without the cache's internals.

#include <cstdint>
#include <string_view>

namespace resoct {

/// The eviction policies a renderer's caches can use (RendererOptions::eviction, host_eviction).
enum class Eviction : std::uint8_t {
  lru,          ///< LruPolicy
  octreemizer,  ///< OctreemizerPolicy, distances from the current camera
};
/// "lru" / "octreemizer".
const char* to_string(Eviction e) noexcept;
/// The inverse of to_string; throws Error(invalid_argument) naming `parameter` otherwise.
Eviction parse_eviction(std::string_view s, std::string_view parameter = "eviction");

}  // namespace resoct
