#pragma once
/// \file
/// The OpenMP CPU backend: runs the single-source traversal kernel (kernel/traverse.glsl.h) over
/// screen tiles. It is the reference the Vulkan backend is tested against.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "resoct/backend/backend.hpp"

namespace resoct {
class RequestSet;  // engine/request_set.hpp: only the backend's .cpp needs it
}  // namespace resoct

namespace resoct::cpu {

/// A CPU backend object for Renderer(source, backend, options): the way a viewer makes one (no
/// registration needed). `threads` <= 0: OpenMP's default thread count.
std::unique_ptr<Backend> make_backend(int threads = 0);

/// Registers the CPU backend under the name "cpu" (idempotent, thread-safe), for name-based
/// creation (create_backend("cpu"), RendererOptions::backend). Call it before: static
/// initializers in shared libraries are unreliable.
void register_backend();

/// Device state in host memory. Not thread-safe (one Renderer drives it). Different CpuBackend
/// instances render at the same time: each render builds its own kernel context.
class CpuBackend : public Backend {
 public:
  /// `threads` <= 0: OpenMP's default thread count.
  explicit CpuBackend(int threads = 0);
  ~CpuBackend() override;

  std::string_view name() const noexcept override { return "cpu"; }
  /// Throws Error(invalid_argument) naming "config" for zero-sized bricks or a cache pool whose
  /// byte size overflows; Error(out_of_memory) when the pool cannot be allocated.
  void configure(const BackendConfig& config) override;
  /// Throws Error(invalid_argument) naming "update" for an upload or delta outside the
  /// configured sizes or a brick of the wrong byte size (device state is then partly updated).
  void update(const FrameUpdate& update) override;
  /// Throws Error(invalid_argument) naming "tables" when the tables do not match the
  /// configuration (sizes, slot counts, LUT size).
  void render(const FrameTables& tables, FrameResult& result) override;

  const BackendConfig& config() const noexcept { return config_; }

 private:
  void check_tables(const FrameTables& tables) const;

  int threads_ = 0;
  BackendConfig config_{};
  bool configured_ = false;
  std::size_t voxel_bytes_ = 1;
  std::size_t slot_voxels_ = 0;
  std::vector<std::byte> cache_;
  std::vector<std::uint32_t> pages_;  // the page pool
  std::vector<std::uint32_t> directory_;
  std::vector<std::uint32_t> directory_offsets_;
  std::vector<std::uint32_t> nodes_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> used_bits_;
  std::size_t used_words_ = 0;
  std::unique_ptr<RequestSet> brick_requests_;
  std::unique_ptr<RequestSet> node_requests_;
};

}  // namespace resoct::cpu
