// The mask-0 kernel: a scene without effects runs exactly this (see kernel_access.hpp), compiled
// per render mode and for one channel or several (kernel/effects.glsl.h, RESOCT_FX_MODE and
// RESOCT_FX_SLOT_COUNT), so that the march of one mode carries no branch of the others and a
// single-channel frame no channel loop. Frames with error-bounded LOD run the mask-0 kernel that
// reads mode and channel count at run time.
#include "kernel_access.hpp"

namespace resoct::cpu::detail {
namespace {

template <std::uint32_t MODE>
RayTotals render_mode(const KernelContext& ctx, const kernel::ResoctFrame& frame, glm::vec4* pixels,
                      int threads) {
  using namespace kernel;
  if (frame.slot_count == 1u) {
    return render_tiles<resoct_fx_with_mode(RESOCT_EFFECT_ONE_SLOT, MODE)>(ctx, frame, pixels,
                                                                           threads);
  }
  return render_tiles<resoct_fx_with_mode(0u, MODE)>(ctx, frame, pixels, threads);
}

}  // namespace

RayTotals render_plain(const KernelContext& ctx, const kernel::ResoctFrame& frame,
                       glm::vec4* pixels, int threads) {
  using namespace kernel;
  // Error-bounded LOD lives only in the kernel that is not specialized per mode
  // (resoct_fx_error_lod), so that the others carry none of its checks.
  for (std::uint32_t i = 0; i < frame.slot_count; ++i) {
    if (ctx.slots[i].lod_error_code != 0u) return render_tiles<0u>(ctx, frame, pixels, threads);
  }
  switch (frame.mode) {
    case RESOCT_MODE_RESIDENCY:
      return render_mode<RESOCT_MODE_RESIDENCY>(ctx, frame, pixels, threads);
    case RESOCT_MODE_OCTREE: return render_mode<RESOCT_MODE_OCTREE>(ctx, frame, pixels, threads);
    // The page table; the kernel treats any other mode value as it does.
    default: return render_mode<RESOCT_MODE_PAGETABLE>(ctx, frame, pixels, threads);
  }
}

}  // namespace resoct::cpu::detail
