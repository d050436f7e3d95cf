// The mask-0 kernel: a scene without effects runs exactly this (see kernel_access.hpp).
#include "kernel_access.hpp"

namespace resoct::cpu::detail {

RayTotals render_plain(const KernelContext& ctx, const kernel::ResoctFrame& frame,
                       glm::vec4* pixels, int threads) {
  return render_tiles<0u>(ctx, frame, pixels, threads);
}

}  // namespace resoct::cpu::detail
