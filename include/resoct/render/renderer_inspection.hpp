#pragma once
/// \file
/// Inspection of a Renderer's engine: its page table, device brick cache, residency octree and
/// layout, channel map, loader, backend and backend configuration. A viewer never needs this
/// header (renderer.hpp is the viewer's); it is for the tests, which check the engine's state
/// frame by frame, and for the tools, benchmarks and the Python module, which report statistics
/// the engine keeps (cache slots, loader counters) or ask the backend for its device.
///
/// Each function returns a reference to the Renderer's own object, valid as long as the
/// Renderer; the const ones only read. None of them is part of the viewer API, and the engine's
/// types they return may change with the frame loop.

#include "resoct/backend/backend.hpp"
#include "resoct/engine/brick_cache.hpp"
#include "resoct/engine/brick_loader.hpp"
#include "resoct/engine/channel_map.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/residency_octree.hpp"
#include "resoct/render/renderer.hpp"

namespace resoct::inspect {

/// The residency octree's subdivision (RendererOptions::leaf_size).
const OctreeLayout& layout(const Renderer& r) noexcept;
/// The multi-channel page table, as the backend mirrors it.
const PageTable& page_table(const Renderer& r) noexcept;
/// The device brick cache's bookkeeping (slots, residency, pins).
const BrickCache& cache(const Renderer& r) noexcept;
/// The residency octree (host copy; the backend receives its word deltas).
const ResidencyOctree& octree(const Renderer& r) noexcept;
/// Which dataset channel each visible slot shows.
const ChannelMap& channel_map(const Renderer& r) noexcept;
/// The loader threads and the host cache of decoded bricks.
const BrickLoader& loader(const Renderer& r) noexcept;
/// The backend the Renderer renders with.
Backend& backend(Renderer& r) noexcept;
/// The sizes the backend was configured with.
const BackendConfig& backend_config(const Renderer& r) noexcept;

}  // namespace resoct::inspect
