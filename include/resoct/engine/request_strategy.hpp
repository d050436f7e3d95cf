#pragma once
/// \file
/// The choice of request strategy (RendererOptions::strategy) and its names, apart from the
/// request set and the strategies' code (request_set.hpp), so that the renderer's options name
/// it without the engine's internals.

#include <cstdint>
#include <string_view>

namespace resoct {

/// How a ray that misses its target brick asks for data (paper 002 §5.3.2).
enum class RequestStrategy : std::uint8_t {
  greedy,  ///< the target and every coarser level on the way up
  global,  ///< only the target
};
/// "greedy" / "global".
const char* to_string(RequestStrategy s) noexcept;
/// The inverse of to_string; throws Error(invalid_argument) naming `parameter` otherwise.
RequestStrategy parse_request_strategy(std::string_view s, std::string_view parameter = "strategy");

}  // namespace resoct
