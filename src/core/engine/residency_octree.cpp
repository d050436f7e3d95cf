// Residency octree: construction, residency bit updates, remapping and word deltas. Metadata
// lives in residency_octree_meta.cpp, the brute-force check in residency_octree_check.cpp.
#include "resoct/engine/residency_octree.hpp"

#include <algorithm>
#include <cmath>
#include <new>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

namespace {
constexpr double kQuantMax = 65535.0;

double quant_position(double v, const ValueRange& r) noexcept {
  return (v - r.lo) / (r.hi - r.lo) * kQuantMax;
}
}  // namespace

double octree_dequantize(std::uint32_t q, const ValueRange& r) noexcept {
  return r.lo + double(q) * (r.hi - r.lo) / kQuantMax;
}

std::uint32_t octree_quantize_min(double v, const ValueRange& r) noexcept {
  if (std::isnan(v)) return 0u;
  const double t = quant_position(v, r);
  if (!(t > 0.0)) return 0u;
  if (t >= kQuantMax) return 65535u;
  // floor() of a rounded quotient can land one step too high; step down until the dequantized
  // value (the one culling compares against) really is below v.
  auto q = std::uint32_t(std::floor(t));
  while (q > 0 && octree_dequantize(q, r) > v) --q;
  return q;
}

std::uint32_t octree_quantize_max(double v, const ValueRange& r) noexcept {
  if (std::isnan(v)) return 65535u;
  const double t = quant_position(v, r);
  if (!(t < kQuantMax)) return 65535u;
  if (t <= 0.0) return 0u;
  auto q = std::uint32_t(std::ceil(t));
  while (q < 65535u && octree_dequantize(q, r) < v) ++q;
  return q;
}

std::uint32_t octree_pack_range(double min, double max, const ValueRange& r) noexcept {
  if (std::isnan(min) || std::isnan(max) || min > max) return 0u;
  return kernel::resoct_node_pack_minmax(octree_quantize_min(min, r), octree_quantize_max(max, r));
}

ResidencyOctree::ResidencyOctree(const BrickHierarchy& hierarchy, OctreeLayout layout,
                                 std::uint32_t slots, ResidencyQuery query)
    : hierarchy_(hierarchy), layout_(std::move(layout)), slots_(slots), query_(std::move(query)) {
  if (layout_.extent0() != hierarchy_.volume().extent) {
    throw invalid_parameter("layout", "octree layout extent differs from the volume extent");
  }
  if (slots_ == 0 || slots_ > kMaxChannels) {
    throw invalid_parameter(
        "slots", "must be 1.." + std::to_string(kMaxChannels) + ", got " + std::to_string(slots_));
  }
  if (!query_) throw invalid_parameter("query", "the residency query must be callable");
  const std::uint64_t words = layout_.node_count() * slots_ * 4u;
  if (words > 0xffffffffull) {
    throw invalid_parameter("slots", std::to_string(layout_.node_count()) + " nodes x " +
                                         std::to_string(slots_) +
                                         " slots exceed 2^32 device words; use larger leaves");
  }
  try {
    words_.assign(std::size_t(words), 0u);
    dirty_bits_.assign(std::size_t((words + 63) / 64), 0u);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::out_of_memory, "residency octree: cannot allocate " +
                                              std::to_string(words * 4u) + " bytes of node words");
  }
  ranges_.assign(slots_, default_range(hierarchy_.volume().type));
}

void ResidencyOctree::set_word(std::size_t index, std::uint32_t value) {
  if (words_[index] == value) return;
  words_[index] = value;
  ++stats_.words_changed;
  if (dirty_full_) return;
  std::uint64_t& bits = dirty_bits_[index / 64];
  const std::uint64_t mask = std::uint64_t(1) << (index % 64);
  if (bits & mask) return;
  bits |= mask;
  dirty_list_.push_back(std::uint32_t(index));
  // Past a quarter of the storage a full upload is cheaper than a delta list.
  if (dirty_list_.size() > words_.size() / 4 + 64) dirty_full_ = true;
}

OctreeDeltas ResidencyOctree::take_deltas() {
  OctreeDeltas out;
  if (dirty_full_) {
    out.full = true;
    std::fill(dirty_bits_.begin(), dirty_bits_.end(), 0u);
  } else {
    out.words.reserve(dirty_list_.size());
    for (std::uint32_t i : dirty_list_) {
      out.words.push_back({i, words_[i]});
      dirty_bits_[i / 64] &= ~(std::uint64_t(1) << (i % 64));
    }
  }
  dirty_list_.clear();
  dirty_full_ = false;
  return out;
}

std::uint32_t ResidencyOctree::word(std::uint64_t node, std::uint32_t slot,
                                    std::uint32_t which) const {
  check_slot(slot);
  if (node >= layout_.node_count() || which >= kernel::RESOCT_NODE_WORDS) {
    throw Error(ErrorCode::out_of_range, "octree word (node " + std::to_string(node) + ", word " +
                                             std::to_string(which) + ") does not exist");
  }
  return words_[base(node, slot) + which];
}

void ResidencyOctree::check_slot(std::uint32_t slot) const {
  if (slot >= slots_) {
    throw Error(ErrorCode::out_of_range, "slot " + std::to_string(slot) + " past the " +
                                             std::to_string(slots_) + " visible slots");
  }
}

void ResidencyOctree::check_brick(std::uint32_t level, glm::uvec3 brick) const {
  if (level >= hierarchy_.level_count()) {
    throw Error(ErrorCode::out_of_range, "level " + std::to_string(level) + " past the " +
                                             std::to_string(hierarchy_.level_count()) + " levels");
  }
  const glm::uvec3 n = hierarchy_.level(level).bricks;
  if (brick.x >= n.x || brick.y >= n.y || brick.z >= n.z) {
    throw Error(ErrorCode::out_of_range,
                "brick (" + std::to_string(brick.x) + ", " + std::to_string(brick.y) + ", " +
                    std::to_string(brick.z) + ") outside level " + std::to_string(level));
  }
}

void ResidencyOctree::remap_slot(std::uint32_t slot, const ValueRange& range) {
  check_slot(slot);
  if (!std::isfinite(range.lo) || !std::isfinite(range.hi) || !(range.lo < range.hi)) {
    throw invalid_parameter("range", "must be finite with lo < hi");
  }
  ranges_[slot] = range;
  for (std::uint64_t n = 0; n < layout_.node_count(); ++n) {
    const std::size_t b = base(n, slot);
    for (std::size_t w = 0; w < 4; ++w) set_word(b + w, 0u);
  }
  for (auto it = own_.begin(); it != own_.end();) {
    it = it->first % slots_ == slot ? own_.erase(it) : std::next(it);
  }
}

void ResidencyOctree::brick_added(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick) {
  check_slot(slot);
  check_brick(level, brick);
  const Box3 box = hierarchy_.level0_box(level, brick);
  const std::uint32_t bit = 1u << level;
  // Depth by depth from the leaves: the nodes overlapping the brick at depth d are exactly the
  // parents of those at d + 1, and once a whole depth is unchanged every ancestor already has
  // the bit (parent = OR of children).
  NodeCoordRange range = layout_.leaf_range(box);
  if (range.empty()) return;
  for (std::uint32_t d = layout_.leaf_depth();; --d) {
    bool changed = false;
    layout_.for_each_node(d, range, [&](std::uint64_t node, glm::uvec3) {
      ++stats_.nodes_visited;
      const std::size_t i = base(node, slot);
      if ((words_[i] & bit) == 0) {
        set_word(i, words_[i] | bit);
        changed = true;
      }
    });
    if (!changed || d == 0) break;
    range = layout_.parent_range(d, range);
  }
}

bool ResidencyOctree::other_brick_resident(std::uint32_t slot, std::uint32_t level,
                                           glm::uvec3 evicted, const Box3& leaf_box) {
  const Box3 lv = hierarchy_.level_box_from_level0(level, leaf_box);
  const glm::i64vec3 bs(hierarchy_.layout().brick_size);
  const glm::i64vec3 nb(hierarchy_.level(level).bricks);
  const glm::i64vec3 lo = glm::clamp(lv.lo / bs, glm::i64vec3(0), nb);
  const glm::i64vec3 hi = glm::clamp((lv.hi + bs - glm::i64vec3(1)) / bs, glm::i64vec3(0), nb);
  for (std::int64_t z = lo.z; z < hi.z; ++z) {
    for (std::int64_t y = lo.y; y < hi.y; ++y) {
      for (std::int64_t x = lo.x; x < hi.x; ++x) {
        const glm::uvec3 b{std::uint32_t(x), std::uint32_t(y), std::uint32_t(z)};
        if (b == evicted) continue;
        ++stats_.residency_queries;
        if (query_(slot, level, b)) return true;
      }
    }
  }
  return false;
}

void ResidencyOctree::brick_evicted(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick) {
  check_slot(slot);
  check_brick(level, brick);
  const Box3 box = hierarchy_.level0_box(level, brick);
  const std::uint32_t bit = 1u << level;
  const std::uint32_t leaf = layout_.leaf_depth();
  NodeCoordRange range = layout_.leaf_range(box);
  bool changed = false;
  layout_.for_each_node(leaf, range, [&](std::uint64_t node, glm::uvec3 c) {
    ++stats_.nodes_visited;
    const std::size_t i = base(node, slot);
    if ((words_[i] & bit) == 0) return;
    const Box3 lb = layout_.node_box(leaf, c);
    // A leaf inside the brick's box overlaps no other brick of this level: no query needed.
    const bool inside = intersect(lb, box) == lb;
    if (!inside && other_brick_resident(slot, level, brick, lb)) return;
    set_word(i, words_[i] & ~bit);
    changed = true;
  });
  for (std::uint32_t d = leaf; d-- > 0 && changed;) {
    changed = false;
    range = layout_.parent_range(d + 1, range);
    const OctreeDepth& here = layout_.depth(d);
    const OctreeDepth& next = layout_.depth(d + 1);
    layout_.for_each_node(d, range, [&](std::uint64_t node, glm::uvec3) {
      ++stats_.nodes_visited;
      const std::size_t i = base(node, slot);
      if ((words_[i] & bit) == 0) return;
      const std::uint64_t first = next.first_node + ((node - here.first_node) << next.child_shift);
      const std::uint32_t count = 1u << next.child_shift;
      std::uint32_t any = 0;
      for (std::uint32_t k = 0; k < count && any == 0; ++k) {
        any = words_[base(first + k, slot)] & bit;
      }
      if (any == 0) {
        set_word(i, words_[i] & ~bit);
        changed = true;
      }
    });
  }
}

}  // namespace resoct
