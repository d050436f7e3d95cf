#pragma once
/// \file
/// Thread control of the CPU backend (OpenMP). Kept behind plain functions so that consumers
/// never include <omp.h>.

namespace resoct::cpu {

/// Threads the CPU backend uses for rendering and bulk work (OpenMP's current maximum).
int thread_count() noexcept;

/// Sets the thread count for subsequent work; n <= 0 restores the OpenMP default
/// (OMP_NUM_THREADS or the core count). Not thread-safe: call between frames.
void set_thread_count(int n) noexcept;

}  // namespace resoct::cpu
