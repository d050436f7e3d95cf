#pragma once
/// \file
/// The plugin boundary between the host-side structures (owned by Renderer) and a device that
/// renders: the CPU backend (resoct::cpu), the Vulkan backend (resoct::vulkan), or a third-party
/// one. Backends never own residency state: each frame they receive deltas (uploaded bricks,
/// changed page-table entries, changed octree words) plus small per-frame tables, render, and
/// return an image, the frame's requests, the cache slots they used, and statistics.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "resoct/backend/image.hpp"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/engine/device_records.hpp"
#include "resoct/scene/step_lut.hpp"
#include "resoct/scene/transfer_function.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// The three methods compared in paper 000 Table 1, one kernel.
enum class RenderMode : std::uint32_t {
  residency = kernel::RESOCT_MODE_RESIDENCY,
  pagetable = kernel::RESOCT_MODE_PAGETABLE,
  octree = kernel::RESOCT_MODE_OCTREE,
};
const char* to_string(RenderMode m) noexcept;
/// Parses "residency", "pagetable", "octree"; throws Error(invalid_argument) naming "mode".
RenderMode parse_render_mode(std::string_view s);

/// Sizes of the device state, fixed until the next configure().
struct BackendConfig {
  VoxelType voxel_type = VoxelType::u8;
  glm::uvec3 padded_brick{34};    ///< voxels per cache slot per axis (core + 2 halo)
  std::uint32_t cache_slots = 0;  ///< bricks the device cache holds
  /// Blocks of the page pool (PageTable::pool_block_count(), block 0 included), each
  /// RESOCT_PAGE_BLOCK_ENTRIES words.
  std::uint32_t page_pool_blocks = 1;
  std::uint32_t directory_entries = 0;  ///< words of the page directory (PageTable::directory())
  std::uint32_t page_tables = 0;        ///< (slot, level) tables (PageTable::table_count())
  std::uint64_t node_words = 0;         ///< words of the octree (ResidencyOctree::words())
  std::uint32_t brick_request_capacity = 1u << 16;  ///< device request set sizes
  std::uint32_t node_request_capacity = 1u << 14;
  /// Brick bytes the frame loop uploads per frame at most (its UploadBudget); 0 = unknown. A
  /// backend may size staging memory from it; larger updates must still work.
  std::uint64_t upload_bytes_per_frame = 0;
};

/// One brick to place into a cache slot: padded voxels of BackendConfig::voxel_type.
struct BrickUpload {
  std::uint32_t cache_slot = 0;
  std::span<const std::byte> voxels;
};

/// The state changes of one frame. When a `full` flag is set, the matching `all` span holds the
/// complete array and the delta list is empty (e.g. after configure() or a slot remap).
struct FrameUpdate {
  std::span<const BrickUpload> bricks;
  std::span<const PageDelta> page_deltas;       ///< pool words: index = block * 4096 + entry
  std::span<const PageDelta> directory_deltas;  ///< directory words (values < page_pool_blocks)
  bool pages_full = false;
  /// With pages_full: a prefix of the pool (PageTable::pool(); the rest reads UNMAPPED), the
  /// whole directory and the table_count + 1 directory offsets.
  std::span<const std::uint32_t> all_pages;
  std::span<const std::uint32_t> all_directory;
  std::span<const std::uint32_t> directory_offsets;
  std::span<const OctreeWordDelta> node_deltas;
  bool nodes_full = false;
  std::span<const std::uint32_t> all_nodes;
};

/// Small per-frame tables, re-sent whole every frame (built by build_frame_tables()).
struct FrameTables {
  kernel::ResoctFrame frame{};
  kernel::ResoctFxFrame fx{};                   ///< effect constants (kernel/effects.glsl.h)
  std::vector<kernel::ResoctSlotInfo> slots;    ///< visible channels in importance order
  std::vector<kernel::ResoctLevelInfo> levels;  ///< one per hierarchy level
  std::vector<kernel::ResoctDepthInfo> depths;  ///< one per octree depth
  std::vector<glm::vec4> tf_luts;  ///< page_slot_count * RESOCT_TF_LUT_SIZE, indexed by slot
  /// With RESOCT_EFFECT_PREINT in fx.effects: page_slot_count * 2 * RESOCT_TF_LUT_SIZE entries,
  /// indexed by slot (preintegration_table(), kernel/preintegration.glsl.h); else empty.
  std::vector<glm::vec4> preint_tables;
  /// What build_frame_tables() built tf_luts and preint_tables from, so that a build into the
  /// same tables recomputes only what changed (a camera move recomputes no LUT). Per page slot:
  /// the transfer function whose LUT tf_luts holds (none: the LUT is zero), and whether
  /// preint_tables holds that LUT's pre-integration table. Backends do not read these.
  std::vector<std::optional<TransferFunction>> lut_sources;
  std::vector<std::uint8_t> preint_built;
  /// Opacity-corrected, premultiplied LUTs of the frame's step levels (kernel/step_lut.glsl.h):
  /// page_slot_count * frame.step_level_count * RESOCT_TF_LUT_SIZE entries, the LUT of slot s
  /// and level l at (s * step_level_count + l) * RESOCT_TF_LUT_SIZE; slots not shown read zero.
  /// They depend on the transfer functions and the step parameters, not on the camera.
  std::vector<glm::vec4> step_luts;
  /// Per page slot: whether step_luts holds the slot's tables for its tf_luts entry and the
  /// frame's levels (build bookkeeping; backends do not read it).
  std::vector<std::uint8_t> step_luts_built;
  StepLevels step_levels;  ///< the levels step_luts was built for (bookkeeping)
  /// Changes (process-wide counter) whenever step_luts does, so that a backend keeping a device
  /// copy re-sends it only then; equal versions mean equal contents.
  std::uint64_t step_luts_version = 0;
  /// Transfer-function LUTs the last build computed; the other slots' LUTs were kept.
  std::uint32_t luts_built = 0;
  /// Residency mode: one word per octree node whose bit i says that slot-table entry i finds no
  /// node at or below it whose metadata is missing, and too little that its transfer function
  /// hides for a descent to pay (render/visible_subtrees.hpp); the traversal then marches the
  /// node's box as one visible node (hidden nodes inside it sampled, transparent). Empty: no node
  /// has bits (what a backend must read as all zero). Built by the Renderer from the octree it
  /// sends, not by build_frame_tables; otherwise empty.
  std::vector<std::uint32_t> visible_subtrees;
  /// Changes (process-wide counter) whenever visible_subtrees does; equal versions mean equal
  /// contents, 0 means "not versioned" (always send).
  std::uint64_t visible_subtrees_version = 0;
  /// Whether render() must copy the image into host memory (FrameResult::image). When false, a
  /// backend that renders into device memory leaves the pixels there, describes them in
  /// FrameResult::device_image and leaves FrameResult::image as it was; a backend that renders
  /// in host memory (the CPU backend) fills FrameResult::image anyway.
  bool image_to_host = true;
};

/// Per-frame statistics a backend reports (sums over rays).
struct BackendStats {
  std::uint64_t rays = 0;
  std::uint64_t samples = 0;
  std::uint64_t nodes_visited = 0;
  std::uint64_t brick_accesses = 0;
  std::uint64_t iterations = 0;
  std::uint64_t cap_hits = 0;  ///< rays stopped by the iteration cap (must stay 0)
  std::uint64_t request_inserts = 0;
  std::uint64_t requests_dropped = 0;
  std::uint64_t gradient_evals = 0;  ///< gradients computed (shading, isosurface normals)
  std::uint64_t shadow_rays = 0;     ///< shadow rays cast
  double distance_skipped = 0.0;     ///< box units
  double distance_marched = 0.0;     ///< box units
  double ms_render = 0.0;            ///< host wall time of render()
  double ms_device = 0.0;            ///< device time where measurable (timestamp queries), else 0
};

/// A frame's image left in device memory (FrameTables::image_to_host = false), for an
/// application that displays it without a copy to the host. Pixels as FrameResult::image would
/// hold them: RGBA float32 (16 bytes per pixel, straight alpha over the background), row-major,
/// row 0 at the top, no padding between rows. Vulkan: `handle` is the VkBuffer (a storage buffer
/// usable as a transfer source, exclusive to the backend's queue family); the frame's writes are
/// complete when render() returns, and a command buffer that reads them needs a barrier from
/// VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT / VK_ACCESS_SHADER_WRITE_BIT first. The buffer is the
/// backend's: valid until its next render() or configure(), which may write or replace it.
struct DeviceImage {
  std::uint64_t handle = 0;  ///< backend-specific buffer handle; 0 when the image is on the host
  std::uint64_t offset = 0;  ///< bytes from the buffer's start to pixel (0, 0)
  std::uint64_t bytes = 0;   ///< width * height * 16
  std::uint32_t width = 0;
  std::uint32_t height = 0;
};

/// What render() returns.
struct FrameResult {
  Image image;  ///< RGBA over the background, stored straight (docs/rendering.md "Compositing")
  /// Where the image stays on the device (FrameTables::image_to_host = false on a device
  /// backend); handle 0 otherwise.
  DeviceImage device_image;
  /// Device request keys (PageTable::device_key) + hits. Keys name pool blocks, not levels, so
  /// every brick request carries level 0 (the loader orders loads by the decoded brick).
  std::vector<Request> brick_requests;
  std::vector<Request> node_requests;           ///< octree node indices + hits
  std::vector<std::uint32_t> used_cache_slots;  ///< distinct cache slots sampled this frame
  BackendStats stats;
};

/// The nodes of the octree a depth table describes (FrameTables::depths; 0 for an empty table):
/// the size of per-node arrays such as FrameTables::visible_subtrees.
std::uint64_t octree_node_count(std::span<const kernel::ResoctDepthInfo> depths) noexcept;

/// Checks that per-frame tables are consistent with themselves and with the configured sizes, so
/// that a backend never indexes outside its arrays. Throws Error(invalid_argument) naming
/// "tables". Every backend calls it at the start of render().
void check_frame_tables(const FrameTables& tables, const BackendConfig& config);

/// Checks the page-table sizes of a backend configuration against the 32-bit device request keys
/// (kernel/request_key.glsl.h): 1..RESOCT_REQUEST_MAX_POOL_BLOCKS pool blocks and fewer than
/// 2^31 - 1 directory entries. Throws Error(invalid_argument) naming "config". Every backend
/// calls it when it is created.
void check_page_table_config(const BackendConfig& config);

/// A rendering device. Not thread-safe: one Renderer drives it from one thread.
class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string_view name() const noexcept = 0;
  /// Allocates device state for these sizes; all state reads as zero (unmapped, invalid)
  /// afterwards. Throws Error(out_of_memory / device / invalid_argument) when it cannot.
  virtual void configure(const BackendConfig& config) = 0;
  /// Applies one frame's state changes.
  virtual void update(const FrameUpdate& update) = 0;
  /// Renders one frame into `result` (reusing its buffers).
  virtual void render(const FrameTables& tables, FrameResult& result) = 0;
};

/// Options a backend factory receives (each backend documents what it honours).
struct BackendOptions {
  int threads = 0;          ///< CPU: worker threads (0 = all cores)
  std::string device;       ///< Vulkan: device index or name substring ("" = best)
  bool validation = false;  ///< Vulkan: enable validation layers, fail on any message
};

using BackendFactory = std::function<std::unique_ptr<Backend>(const BackendOptions&)>;

/// Registers a backend under a name; a later registration of the same name replaces it.
/// Thread-safe.
void register_backend(const std::string& name, BackendFactory factory);
/// Creates a registered backend; throws Error(invalid_argument) naming "backend" and listing the
/// registered names when `name` is unknown. Thread-safe.
std::unique_ptr<Backend> create_backend(std::string_view name, const BackendOptions& options = {});
/// Names of the registered backends, sorted.
std::vector<std::string> backend_names();

}  // namespace resoct
