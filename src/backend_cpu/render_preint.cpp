// The plain kernel with pre-integrated transfer functions (mask RESOCT_EFFECT_PREINT): a scene
// with "preintegration" and no other effect runs exactly this (see kernel_access.hpp).
#include "kernel_access.hpp"

namespace resoct::cpu::detail {

RayTotals render_preint(const KernelContext& ctx, const kernel::ResoctFrame& frame,
                        glm::vec4* pixels, int threads) {
  return render_tiles<kernel::RESOCT_EFFECT_PREINT>(ctx, frame, pixels, threads);
}

}  // namespace resoct::cpu::detail
