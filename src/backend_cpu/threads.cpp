#include "resoct/cpu/threads.hpp"

#include <omp.h>

namespace resoct::cpu {

namespace {
const int g_default_threads = omp_get_max_threads();
}

int thread_count() noexcept {
  return omp_get_max_threads();
}

void set_thread_count(int n) noexcept {
  omp_set_num_threads(n > 0 ? n : g_default_threads);
}

}  // namespace resoct::cpu
