#include "resoct/render/visible_subtrees.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <string>

#include "resoct/base/error.hpp"
#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/render/traversal_depths.hpp"

namespace resoct {

namespace {

namespace k = kernel;

// The coordinate a local index holds in the bits `mask` (ResoctDepthInfo::axis_bits_*): the
// mask's bits from the lowest up are the coordinate's from its least significant bit.
std::uint32_t extract_bits(std::uint32_t local, std::uint32_t mask) {
  std::uint32_t out = 0;
  for (std::uint32_t bit = 0; mask != 0u; mask &= mask - 1u, ++bit) {
    if ((local & mask & (~mask + 1u)) != 0u) out |= 1u << bit;
  }
  return out;
}

// Whether the node's box lies wholly outside the volume [0, extent): the octree's node counts are
// powers of two, so its last nodes along an axis may hold no voxel. No ray reaches them (rays are
// clipped to the volume) and their records stay INVALID: they must not clear their ancestors' bits.
bool outside_volume(const k::ResoctDepthInfo& D, std::uint32_t local, glm::uvec3 extent) {
  return std::uint64_t(extract_bits(local, D.axis_bits_x)) * D.node_extent_x >= extent.x ||
         std::uint64_t(extract_bits(local, D.axis_bits_y)) * D.node_extent_y >= extent.y ||
         std::uint64_t(extract_bits(local, D.axis_bits_z)) * D.node_extent_z >= extent.z;
}

// A process-wide counter: two producers never hand one backend equal versions of different bits.
std::uint64_t next_visible_subtrees_version() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

float shortest_step(const k::ResoctFrame& f) {
  // The kernel's step (kernel/step.glsl.h resoct_step_size) is min_i h_i / |d_i| over the axes,
  // which for a unit direction is at least min_i h_i: an axis-aligned ray has the shortest. Its
  // step level rounds it down as the kernel does (kernel/step_lut.glsl.h), a monotone rounding.
  float dt = std::min(f.finest_voxel_x, std::min(f.finest_voxel_y, f.finest_voxel_z));
  dt = std::max(dt * f.step_scale, f.min_step);
  if (f.step_level_count != 0u) {
    const float ratio = dt * (1.0f / f.ref_step);
    const std::uint32_t level =
        (std::bit_cast<std::uint32_t>(ratio) >> f.step_level_shift) - f.step_level_first;
    if (level < f.step_level_count) {
      dt = std::bit_cast<float>((f.step_level_first + level) << f.step_level_shift) * f.ref_step;
    }
  }
  return dt;
}

std::uint32_t deepest_traversal_depth(const k::ResoctFrame& f,
                                      std::span<const k::ResoctLevelInfo> levels,
                                      std::span<const k::ResoctDepthInfo> depths,
                                      std::span<const k::ResoctSlotInfo> slots) {
  if (depths.empty()) return 0;
  const std::uint32_t start =
      std::min<std::uint32_t>(f.start_depth, std::uint32_t(depths.size()) - 1);
  std::uint32_t depth = traversal_depth(depths, start, f, shortest_step(f));
  // The finest level any entry samples gives the deepest level cap.
  std::uint32_t finest = 0xFFFFFFFFu;
  for (const k::ResoctSlotInfo& s : slots) {
    if (s.vis_bins != 0u) finest = std::min(finest, s.finest_level);
  }
  if (finest < levels.size())
    depth = std::min(depth, level_depth_cap(depths, start, levels[finest]));
  return depth;
}

void hidden_allowance(const k::ResoctFrame& f, std::span<const k::ResoctDepthInfo> depths,
                      float skip_min_samples, std::vector<std::uint16_t>& out) {
  out.assign(depths.size(), 0u);
  if (!(skip_min_samples > 0.0f)) return;
  const float dt = shortest_step(f);
  for (std::size_t d = 0; d < depths.size(); ++d) {
    const float samples = node_shortest_side(depths[d], f) / dt;
    // A node a ray crosses in fewer samples than skip_min_samples saves fewer however much of it
    // is hidden: the whole fraction (an EMPTY node itself still gets no bit). share is in (0, 1],
    // so the conversion rounds down within [0, kHiddenWhole].
    const float share = samples > skip_min_samples ? skip_min_samples / samples : 1.0f;
    out[d] = std::uint16_t(share * float(kHiddenWhole));
  }
}

void brick_depths(std::span<const k::ResoctLevelInfo> levels,
                  std::span<const k::ResoctSlotInfo> slots, std::vector<std::uint32_t>& out) {
  // Without a depth that holds the level's bricks (node_depth RESOCT_NONE_U, 0xFFFFFFFF), every
  // hidden node blocks: the same value is past every depth.
  constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  out.assign(slots.size(), kNone);
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const std::uint32_t finest = slots[i].finest_level;
    if (finest < levels.size() && levels[finest].node_depth != kNone) {
      out[i] = levels[finest].node_depth;
    }
  }
}

void build_visible_subtrees(std::span<const std::uint32_t> words, std::uint32_t node_slots,
                            std::span<const k::ResoctDepthInfo> depths,
                            std::span<const k::ResoctSlotInfo> slots, glm::uvec3 extent,
                            std::uint32_t start_depth, std::uint32_t depth_limit,
                            std::vector<std::uint32_t>& out,
                            std::span<const std::uint16_t> allowance,
                            std::span<const std::uint32_t> brick_depth) {
  VisibleSubtreeBuilder().build(words, node_slots, depths, slots, extent, start_depth, depth_limit,
                                out, allowance, brick_depth);
}

void build_visible_subtrees(const ResidencyOctree& octree, FrameTables& tables,
                            float skip_min_samples) {
  if (tables.frame.mode != k::RESOCT_MODE_RESIDENCY) {
    tables.visible_subtrees.clear();
    tables.visible_subtrees_version = 0;
    return;
  }
  std::vector<std::uint16_t> allowance;
  hidden_allowance(tables.frame, tables.depths, skip_min_samples, allowance);
  std::vector<std::uint32_t> bricks;
  brick_depths(tables.levels, tables.slots, bricks);
  VisibleSubtreeBuilder().build(
      octree, tables,
      deepest_traversal_depth(tables.frame, tables.levels, tables.depths, tables.slots), allowance,
      bricks);
}

// Whether a hidden node (record at `base`, entry i) consists of whole bricks of the entry's finest
// level that are resident EMPTY pages (only zeros), with the bricks of every coarser level the
// entry samples resident: a march below a set bit finds the finest level's page entries EMPTY and
// skips each brick at one lookup, as the page table does (at a coarser level it samples the
// resident brick, as the page table does), and requests nothing. At the depth of the finest level's
// bricks the record must say "only zeros" (VALID, [0, 0], the entry's raw 0 being its normalized 0)
// and its residency word every level from the finest to the coarsest: the node lies inside exactly
// one brick of each (partial residency is the whole brick there). Above that depth every child must
// be such a node.
bool VisibleSubtreeBuilder::empty_pages(std::span<const std::uint32_t> words, std::uint32_t base,
                                        std::uint32_t depth, std::uint32_t i, bool inner,
                                        std::uint32_t first, std::uint32_t children) const {
  if (brick_depth_.empty() || depth > brick_depth_[i]) return false;
  const k::ResoctSlotInfo& s = slots_[i];
  if (!(s.zero_value == 0.0f)) return false;
  if (k::resoct_node_state(words[base + k::RESOCT_NODE_FLAGS]) != k::RESOCT_NODE_VALID ||
      words[base + k::RESOCT_NODE_MINMAX] != k::resoct_node_pack_minmax(0u, 0u)) {
    return false;
  }
  if (depth == brick_depth_[i]) {
    if (s.coarsest_level >= 32u || s.finest_level > s.coarsest_level) return false;
    const std::uint32_t span = s.coarsest_level - s.finest_level + 1u;
    const std::uint32_t levels = (span >= 32u ? 0xFFFFFFFFu : ((1u << span) - 1u))
                                 << s.finest_level;
    return (words[base + k::RESOCT_NODE_RESIDENCY] & levels) == levels;
  }
  if (!inner) return false;
  const std::uint32_t entries = std::uint32_t(slots_.size());
  for (std::uint32_t c = 0; c < children; ++c) {
    if ((known_[first + c] & (1u << i)) == 0u || hidden_[(first + c) * entries + i] != 0u ||
        (blocked_[first + c] & (1u << i)) != 0u) {
      return false;
    }
  }
  return true;
}

// A node's mask, word and hidden fractions from its record and its children's (the children's
// first, when the node is above the depth limit). The limit's own nodes are checked but their
// children are not: no ray descends past them, and they get no word.
VisibleSubtreeBuilder::NodeResult VisibleSubtreeBuilder::compute(
    std::span<const std::uint32_t> words, std::uint32_t depth, std::uint32_t local,
    std::uint16_t* hidden) const {
  const std::uint32_t entries = std::uint32_t(slots_.size());
  std::fill(hidden, hidden + entries, std::uint16_t(0));
  const k::ResoctDepthInfo& D = depths_[depth];
  if (some_outside_[depth] != 0u && outside_volume(D, local, extent_)) return {shown_, 0u, 0u};
  const bool inner = depth < depth_limit_;
  std::uint32_t children_known = shown_, children_blocked = 0;
  std::uint32_t first = 0, children = 0;
  if (inner) {
    const k::ResoctDepthInfo& below = depths_[depth + 1];
    first = below.first_node + (local << below.child_shift);
    children = 1u << below.child_shift;
    for (std::uint32_t c = 0; c < children; ++c) {
      children_known &= known_[first + c];
      children_blocked |= blocked_[first + c];
    }
  }
  std::uint32_t known = 0, blocked = 0, bits = 0;
  for (std::uint32_t pending = shown_; pending != 0u; pending &= pending - 1u) {
    const std::uint32_t i = std::uint32_t(std::countr_zero(pending));
    const std::uint32_t bit = 1u << i;
    const std::uint32_t base =
        k::resoct_node_base(D.first_node + local, slots_[i].slot, node_slots_);
    const std::uint32_t state = k::resoct_node_state(words[base + k::RESOCT_NODE_FLAGS]);
    if (state == k::RESOCT_NODE_INVALID) continue;  // unknown: no bit here or above
    const std::uint32_t minmax = words[base + k::RESOCT_NODE_MINMAX];
    if (!k::resoct_node_range_visible(minmax, slots_[i].vis_lo16, slots_[i].vis_hi16,
                                      slots_[i].vis_bins)) {
      // Hidden: wholly, and what lies below it is never read (the descent skips it; below a
      // set bit it is sampled, transparent). Whole bricks hidden are never widened over, unless
      // they are resident EMPTY pages, which a march below a set bit skips as cheaply.
      known |= bit;
      if (empty_pages(words, base, depth, i, inner, first, children)) continue;  // hides nothing
      hidden[i] = std::uint16_t(kHiddenWhole);
      if (!brick_depth_.empty() && depth <= brick_depth_[i]) blocked |= bit;
      continue;
    }
    if ((children_known & bit) == 0u) continue;
    known |= bit;
    blocked |= children_blocked & bit;
    if (!inner) continue;
    std::uint32_t sum = 0;
    for (std::uint32_t c = 0; c < children; ++c) sum += hidden_[(first + c) * entries + i];
    hidden[i] = std::uint16_t((sum + children - 1u) / children);  // rounded up: 0 only if none
    const bool homogeneous = state == k::RESOCT_NODE_VALID &&
                             k::resoct_node_min16(minmax) == k::resoct_node_max16(minmax);
    if (!homogeneous && (blocked & bit) == 0u && hidden[i] <= allowance_[depth]) bits |= bit;
  }
  return {known, blocked, bits};
}

void VisibleSubtreeBuilder::build(std::span<const std::uint32_t> words, std::uint32_t node_slots,
                                  std::span<const k::ResoctDepthInfo> depths,
                                  std::span<const k::ResoctSlotInfo> slots, glm::uvec3 extent,
                                  std::uint32_t start_depth, std::uint32_t depth_limit,
                                  std::vector<std::uint32_t>& out,
                                  std::span<const std::uint16_t> allowance,
                                  std::span<const std::uint32_t> brick_depth) {
  nodes_ = 0;
  out.clear();
  if (depths.empty()) return;
  const std::uint64_t nodes = octree_node_count(depths);
  if (words.size() < nodes * node_slots * k::RESOCT_NODE_WORDS) {
    throw invalid_parameter("octree", std::to_string(words.size()) + " words for " +
                                          std::to_string(nodes) + " nodes of " +
                                          std::to_string(node_slots) + " slots");
  }
  const std::uint32_t entries =
      std::min<std::uint32_t>(std::uint32_t(slots.size()), k::RESOCT_MAX_SLOTS);
  shown_ = 0;
  for (std::uint32_t i = 0; i < entries; ++i) {
    if (slots[i].slot >= node_slots) {
      throw invalid_parameter("slots", "entry " + std::to_string(i) + " names slot " +
                                           std::to_string(slots[i].slot) + " of " +
                                           std::to_string(node_slots));
    }
    if (slots[i].vis_bins != 0u) shown_ |= 1u << i;
  }
  if (!allowance.empty() && allowance.size() != depths.size()) {
    throw invalid_parameter("allowance", std::to_string(allowance.size()) + " values for " +
                                             std::to_string(depths.size()) + " depths");
  }
  if (!brick_depth.empty() && brick_depth.size() != slots.size()) {
    throw invalid_parameter("brick_depth", std::to_string(brick_depth.size()) + " values for " +
                                               std::to_string(slots.size()) + " entries");
  }
  brick_depth_.clear();
  if (!brick_depth.empty()) {
    brick_depth_.assign(brick_depth.begin(), brick_depth.begin() + std::ptrdiff_t(entries));
  }
  if (allowance.empty()) {
    allowance_.assign(depths.size(), 0u);
  } else {
    allowance_.assign(allowance.begin(), allowance.end());
  }
  node_slots_ = node_slots;
  depths_.assign(depths.begin(), depths.end());
  slots_.assign(slots.begin(), slots.begin() + entries);
  extent_ = extent;
  start_depth_ = start_depth;
  depth_limit_ = std::min<std::uint32_t>(depth_limit, std::uint32_t(depths.size()) - 1);
  // Only a depth whose last nodes along an axis start past the volume has nodes outside it.
  some_outside_.assign(depths.size(), 0u);
  for (std::size_t d = 0; d < depths.size(); ++d) {
    const k::ResoctDepthInfo& D = depths[d];
    some_outside_[d] = std::uint64_t(D.count_x - 1u) * D.node_extent_x >= extent.x ||
                       std::uint64_t(D.count_y - 1u) * D.node_extent_y >= extent.y ||
                       std::uint64_t(D.count_z - 1u) * D.node_extent_z >= extent.z;
  }
  known_.assign(std::size_t(nodes), 0u);
  blocked_.assign(std::size_t(nodes), 0u);
  hidden_.assign(std::size_t(nodes) * entries, 0u);
  out.assign(std::size_t(nodes), 0u);
  nodes_ = nodes;
  if (shown_ == 0u || depth_limit_ <= start_depth_) return;
  // Bottom-up from the depth limit, so that every node finds its children's masks.
  for (std::uint32_t d = depth_limit_ + 1; d-- > start_depth_;) {
    const k::ResoctDepthInfo& D = depths_[d];
    const std::uint32_t count = D.count_x * D.count_y * D.count_z;
    for (std::uint32_t local = 0; local < count; ++local) {
      const std::uint32_t node = D.first_node + local;
      const NodeResult r = compute(words, d, local, hidden_.data() + std::size_t(node) * entries);
      known_[node] = r.known;
      blocked_[node] = r.blocked;
      out[node] = r.bits;
    }
  }
}

VisibleSubtreeUpdate VisibleSubtreeBuilder::update(std::span<const std::uint32_t> words,
                                                   std::span<const std::uint32_t> nodes,
                                                   std::vector<std::uint32_t>& out) {
  if (nodes_ == 0 || out.size() != nodes_ ||
      words.size() < nodes_ * node_slots_ * k::RESOCT_NODE_WORDS) {
    throw invalid_parameter("octree", "update of visible subtrees without a build of this tree");
  }
  VisibleSubtreeUpdate result;
  if (shown_ == 0u || depth_limit_ <= start_depth_) return result;
  pending_.resize(depths_.size());
  for (std::vector<std::uint32_t>& p : pending_) p.clear();
  for (const std::uint32_t node : nodes) {
    if (node >= nodes_) {
      throw invalid_parameter("nodes",
                              "node " + std::to_string(node) + " of " + std::to_string(nodes_));
    }
    // The depth holding the node: the last one starting at or before it.
    std::uint32_t d = std::uint32_t(depths_.size()) - 1;
    while (depths_[d].first_node > node) --d;
    // Records below the limit are never read, and no node above the start depth has a word.
    if (d >= start_depth_ && d <= depth_limit_) pending_[d].push_back(node - depths_[d].first_node);
  }
  // Deepest first: a node is recomputed after its changed children, and its parent is queued
  // only when its mask or a hidden fraction changed (a word alone changing stops there).
  const std::size_t entries = slots_.size();
  std::uint16_t hidden[k::RESOCT_MAX_SLOTS];
  for (std::uint32_t d = depth_limit_ + 1; d-- > start_depth_;) {
    std::vector<std::uint32_t>& locals = pending_[d];
    std::sort(locals.begin(), locals.end());
    locals.erase(std::unique(locals.begin(), locals.end()), locals.end());
    const k::ResoctDepthInfo& D = depths_[d];
    for (const std::uint32_t local : locals) {
      const std::uint32_t node = D.first_node + local;
      const NodeResult r = compute(words, d, local, hidden);
      ++result.recomputed;
      if (out[node] != r.bits) {
        out[node] = r.bits;
        ++result.words_changed;
      }
      std::uint16_t* kept = hidden_.data() + std::size_t(node) * entries;
      if (r.known != known_[node] || r.blocked != blocked_[node] ||
          !std::equal(hidden, hidden + entries, kept)) {
        known_[node] = r.known;
        blocked_[node] = r.blocked;
        std::copy(hidden, hidden + entries, kept);
        if (d > start_depth_) pending_[d - 1].push_back(local >> D.child_shift);
      }
    }
  }
  return result;
}

void VisibleSubtreeBuilder::build(const ResidencyOctree& octree, FrameTables& tables,
                                  std::uint32_t depth_limit,
                                  std::span<const std::uint16_t> allowance,
                                  std::span<const std::uint32_t> brick_depth) {
  build(octree.words(), tables.frame.node_slot_count, tables.depths, tables.slots,
        glm::uvec3(tables.frame.extent_x, tables.frame.extent_y, tables.frame.extent_z),
        tables.frame.start_depth, depth_limit, tables.visible_subtrees, allowance, brick_depth);
  tables.visible_subtrees_version = next_visible_subtrees_version();
}

VisibleSubtreeUpdate VisibleSubtreeBuilder::update(const ResidencyOctree& octree,
                                                   std::span<const std::uint32_t> nodes,
                                                   FrameTables& tables) {
  const VisibleSubtreeUpdate result = update(octree.words(), nodes, tables.visible_subtrees);
  if (result.words_changed != 0) tables.visible_subtrees_version = next_visible_subtrees_version();
  return result;
}

}  // namespace resoct
