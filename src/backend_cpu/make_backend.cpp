// The CPU backend as an object for Renderer(source, backend, options), apart from the kernel
// code in cpu_backend.cpp.
#include "resoct/cpu/cpu_backend.hpp"

namespace resoct::cpu {

std::unique_ptr<Backend> make_backend(int threads) {
  return std::make_unique<CpuBackend>(threads);
}

}  // namespace resoct::cpu
