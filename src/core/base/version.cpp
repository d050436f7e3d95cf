// Compiled into the library: these answer with the headers the library was built from, which an
// application compares with the headers it was built from.
#include "resoct/version.hpp"

namespace resoct {

const char* library_version() noexcept {
  return RESOCT_VERSION_STRING;
}

std::uint32_t library_kernel_layout_version() noexcept {
  return kKernelLayoutVersion;
}

}  // namespace resoct
