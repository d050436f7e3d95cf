#pragma once
/// \file
/// The small records the engine and a backend exchange every frame (backend/backend.hpp:
/// FrameUpdate carries word deltas, FrameResult returns requests), apart from the structures that
/// make and consume them: the page table (page_table.hpp), the residency octree
/// (residency_octree.hpp) and the request set (request_set.hpp).

#include <cstdint>

namespace resoct {

/// One changed page-table word: its index (in PageTable::pool() or ::directory()) and its value
/// at take_deltas() time.
struct PageDelta {
  std::uint32_t index = 0;
  std::uint32_t value = 0;
  friend bool operator==(const PageDelta&, const PageDelta&) = default;
};

/// One changed octree word (ResidencyOctree::words()): storage index and its new value.
struct OctreeWordDelta {
  std::uint32_t index = 0;
  std::uint32_t value = 0;
  friend bool operator==(const OctreeWordDelta&, const OctreeWordDelta&) = default;
};

/// One drained request: its key, how many inserts asked for it (screen coverage: rays), and the
/// level used for ordering (larger = coarser).
struct Request {
  std::uint32_t key = 0;
  std::uint32_t hits = 0;
  std::uint32_t level = 0;
  friend bool operator==(const Request&, const Request&) = default;
};

}  // namespace resoct
