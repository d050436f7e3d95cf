#pragma once
// "Everything resident" for tests: loads every brick of the chosen levels of the chosen channels
// of a source into host structures exactly as the renderer's loader would (PageTable entries
// MAPPED / EMPTY / HOMOGENEOUS from brick_meta, ResidencyOctree brick_added for every present
// brick and node_metadata from region_meta for every leaf), and uploads them to any Backend.
// Channel i of `channels` occupies slot i.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "resoct/backend/backend.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/render/frame_tables.hpp"
#include "resoct/render/renderer_options.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/residency_octree.hpp"

namespace resoct::test {

struct ResidentOptions {
  glm::uvec3 leaf_size{8};
  /// Which levels are loaded (default: all).
  std::function<bool(std::uint32_t level)> level_resident;
  /// Which bricks of a resident level are loaded (default: all); checked before any read.
  std::function<bool(std::uint32_t level, glm::uvec3 brick)> brick_resident;
  /// Supply region metadata for every node of `metadata_depth` (otherwise all records stay
  /// INVALID). Deeper nodes stay INVALID; shallower ones get it by propagation.
  bool metadata = true;
  /// Depth that receives metadata; clamped to the leaf depth (the default).
  std::uint32_t metadata_depth = ~0u;
  /// Give every MAPPED and HOMOGENEOUS entry of level >= 1 its brick_error() code, as the
  /// renderer's loader does with ViewerOptions::brick_errors (error-bounded LOD).
  bool brick_errors = false;
};

class ResidentScene {
 public:
  ResidentScene(const BrickSource& source, std::vector<std::uint32_t> channels,
                const ResidentOptions& options = {});

  const BrickHierarchy& hierarchy() const { return source_.hierarchy(); }
  const OctreeLayout& layout() const { return layout_; }
  const ChannelMap& channel_map() const { return channels_; }
  const PageTable& pages() const { return *pages_; }
  const ResidencyOctree& octree() const { return *octree_; }
  std::uint32_t mapped_bricks() const { return std::uint32_t(uploads_.size()); }

  /// configure() with sizes that fit, then one full update.
  void upload(Backend& backend) const;
  /// build_frame_tables() and, as the Renderer builds them, the visible-subtree bits with
  /// `skip_min_samples` (TuningOptions::skip_min_samples).
  FrameTables tables(const Scene& scene, const FrameOptions& options = {},
                     float skip_min_samples = kDefaultSkipMinSamples) const;
  /// The brick key a device request key names (for asserting requests).
  PageAddress decode(std::uint32_t device_key) const;

 private:
  const BrickSource& source_;
  OctreeLayout layout_;
  ChannelMap channels_;
  std::unique_ptr<PageTable> pages_;
  std::unique_ptr<ResidencyOctree> octree_;
  std::vector<std::byte> voxels_;  // all mapped bricks, padded, back to back
  std::vector<BrickUpload> uploads_;
};

}  // namespace resoct::test
