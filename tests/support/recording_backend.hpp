#pragma once
// A test-only Backend: keeps a mirror of everything the Renderer sends (page entries, octree
// words, cache slot voxels), checks the shape of each update, and answers render() through a
// script, so that frame-loop bookkeeping can be tested without a traversal kernel.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "resoct/backend/backend.hpp"
#include "resoct/engine/page_table.hpp"

namespace resoct::test {

/// What one update() carried.
struct RecordedUpdate {
  std::vector<std::uint32_t> upload_slots;
  std::uint64_t upload_bytes = 0;
  bool pages_full = false;
  bool nodes_full = false;
  std::size_t page_deltas = 0;
  std::size_t node_deltas = 0;
};

class RecordingBackend final : public Backend {
 public:
  /// Fills the result of one frame (image already sized, request lists empty).
  using Script = std::function<void(const FrameTables&, FrameResult&, RecordingBackend&)>;

  std::string_view name() const noexcept override { return "recording"; }
  void configure(const BackendConfig& config) override;
  /// Applies the update to the mirror; throws std::logic_error when it is malformed (wrong
  /// sizes, delta index out of range, full flag without array, upload to a bad slot).
  void update(const FrameUpdate& update) override;
  void render(const FrameTables& tables, FrameResult& result) override;

  void set_script(Script s) { script_ = std::move(s); }
  const BackendConfig& config() const noexcept { return config_; }
  std::uint32_t configure_calls() const noexcept { return configure_calls_; }
  /// The page pool mirror (all page_pool_blocks blocks) and the directory mirror.
  const std::vector<std::uint32_t>& pages() const noexcept { return pages_; }
  const std::vector<std::uint32_t>& directory() const noexcept { return directory_; }
  const std::vector<std::uint32_t>& nodes() const noexcept { return nodes_; }
  std::span<const std::byte> slot_voxels(std::uint32_t slot) const;
  const std::vector<RecordedUpdate>& updates() const noexcept { return updates_; }
  const std::vector<FrameTables>& tables() const noexcept { return tables_; }
  std::uint64_t slot_bytes() const noexcept;

  /// A minimal kernel model for scripts: for each wanted brick, a MAPPED mirror entry counts as
  /// a used cache slot, an UNMAPPED one as a request (one hit; a block-miss key when the mirror's
  /// block is unallocated, as the kernel reports), EMPTY/HOMOGENEOUS as neither.
  void want(const PageTable& table, std::span<const PageAddress> bricks, FrameResult& result);

 private:
  BackendConfig config_;
  std::uint32_t configure_calls_ = 0;
  std::vector<std::uint32_t> pages_;
  std::vector<std::uint32_t> directory_;
  std::vector<std::uint32_t> nodes_;
  std::vector<std::byte> voxels_;
  std::vector<RecordedUpdate> updates_;
  std::vector<FrameTables> tables_;
  Script script_;
};

/// Registers the backend "recording"; each created instance becomes last_recording_backend().
void register_recording_backend();
RecordingBackend* last_recording_backend();

}  // namespace resoct::test
