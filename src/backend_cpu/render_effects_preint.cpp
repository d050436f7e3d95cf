// The kernel instantiated for every effect mask with pre-integration (17 .. 31,
// kernel/effects.glsl.h), chosen once per frame. A unit of its own: sixteen more kernel copies
// in render_effects.cpp would double that unit's compile time and memory.
#include <array>
#include <utility>

#include "kernel_access.hpp"

namespace resoct::cpu::detail {
namespace {

using TileRenderer = RayTotals (*)(const KernelContext&, const kernel::ResoctFrame&, glm::vec4*,
                                   int);

template <std::uint32_t... Masks>
constexpr std::array<TileRenderer, sizeof...(Masks)> make_renderers(
    std::integer_sequence<std::uint32_t, Masks...>) {
  return {&render_tiles<Masks | kernel::RESOCT_EFFECT_PREINT>...};
}

// Index m holds mask m | RESOCT_EFFECT_PREINT (index 0 is never chosen: render_preint.cpp).
constexpr auto kRenderers =
    make_renderers(std::make_integer_sequence<std::uint32_t, kernel::RESOCT_EFFECT_PREINT>());

}  // namespace

RayTotals render_effects_preint(std::uint32_t mask, const KernelContext& ctx,
                                const kernel::ResoctFrame& frame, glm::vec4* pixels, int threads) {
  return kRenderers[mask % kernel::RESOCT_EFFECT_PREINT](ctx, frame, pixels, threads);
}

}  // namespace resoct::cpu::detail
