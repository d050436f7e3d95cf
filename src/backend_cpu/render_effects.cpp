// The kernel instantiated for every non-zero effect mask (kernel/effects.glsl.h), chosen once
// per frame.
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
  return {&render_tiles<Masks>...};
}

// Masks 0 .. 15 (0 is never chosen here: render_plain.cpp).
constexpr auto kRenderers =
    make_renderers(std::make_integer_sequence<std::uint32_t, kernel::RESOCT_EFFECT_PREINT>());

}  // namespace

RayTotals render_effects(std::uint32_t mask, const KernelContext& ctx,
                         const kernel::ResoctFrame& frame, glm::vec4* pixels, int threads) {
  return kRenderers[mask % kernel::RESOCT_EFFECT_PREINT](ctx, frame, pixels, threads);
}

}  // namespace resoct::cpu::detail
