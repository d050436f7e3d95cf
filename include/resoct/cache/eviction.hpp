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
  lru,  ///< LruPolicy
  /// OctreemizerPolicy as published: d = neighbourhood distance in bricks to the wish list tree
  /// of the last frame (WishListDistance)
  octreemizer,
  octreemizer_camera,  ///< OctreemizerPolicy with d = distance from the current camera
};
/// "lru" / "octreemizer" / "octreemizer-camera".
const char* to_string(Eviction e) noexcept;
/// The inverse of to_string; throws Error(invalid_argument) naming `parameter` otherwise.
Eviction parse_eviction(std::string_view s, std::string_view parameter = "eviction");

}  // namespace resoct
