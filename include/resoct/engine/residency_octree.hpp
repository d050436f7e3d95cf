#pragma once
/// \file
/// The residency octree (paper 000 §5, thesis ch. 6 and §8.4): per node and visible channel slot,
/// which resolution levels are partially resident and conservative value metadata for culling.
/// The host copy is authoritative; backends receive word deltas. See docs/residency-octree.md.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>

#include "resoct/engine/device_records.hpp"
#include "resoct/engine/leaf_scan.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/volume/hierarchy.hpp"
#include "resoct/engine/octree_layout.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct {

/// Tells whether the brick (slot, level, brick) is resident in the brick cache right now. The
/// page table provides it; it must already reflect an eviction when brick_evicted() is called.
using ResidencyQuery =
    std::function<bool(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick)>;

/// The changes since the last take_deltas(). When `full` is set so many words changed (e.g. after
/// remap_slot()) that the backend should re-upload all of words(); `words` is then empty.
/// Otherwise `words` lists each changed word once, in the order of its first change (sorting
/// would cost more than the updates themselves; device scatters do not need it).
struct OctreeDeltas {
  bool full = false;
  std::vector<OctreeWordDelta> words;
};

/// Work counters, cumulative since construction or reset_stats().
struct OctreeUpdateStats {
  std::uint64_t nodes_visited = 0;      ///< (node, slot) records read during updates
  std::uint64_t words_changed = 0;      ///< stored words whose value changed
  std::uint64_t residency_queries = 0;  ///< ResidencyQuery calls made by brick_evicted()
};

/// Quantizes v over r to 16 bits rounding DOWN (for minima): the dequantized value
/// r.lo + q * (r.hi - r.lo) / 65535 is <= clamp(v, r.lo, r.hi). NaN gives 0.
std::uint32_t octree_quantize_min(double v, const ValueRange& r) noexcept;
/// Quantizes v over r to 16 bits rounding UP (for maxima): dequantized >= clamp(v, r.lo, r.hi).
/// NaN gives 0xffff.
std::uint32_t octree_quantize_max(double v, const ValueRange& r) noexcept;
/// r.lo + q * (r.hi - r.lo) / 65535.
double octree_dequantize(std::uint32_t q, const ValueRange& r) noexcept;
/// The min/max word (kernel/octree_node.glsl.h) of a conservative [min, max]; 0 ("no values")
/// when min > max, as for a region of only NaN.
std::uint32_t octree_pack_range(double min, double max, const ValueRange& r) noexcept;

/// Residency and culling metadata per octree node and visible slot.
///
/// Residency: bit l of a (node, slot) residency word is set exactly when some resident brick of
/// level l of that slot overlaps the node's box (partial residency).
///
/// Metadata: each (node, slot) record is INVALID, VALID (conservative) or APPROX (estimated from
/// coarse bricks). Its min/max/occupancy is the union of what was supplied for the node itself
/// and of its children's records, so a parent is never narrower than a child. It is VALID when
/// conservative data was supplied for the node (node_metadata() or a level-0 brick) or when every
/// non-empty child is VALID; otherwise APPROX when coarse-brick data was supplied for it or every
/// non-empty child is VALID or APPROX; otherwise INVALID. Metadata is independent of residency and
/// survives eviction. Records nobody touched stay all-zero (INVALID).
///
/// Not thread-safe: one thread (the frame loop) owns it. words() may be read concurrently only
/// while no mutating call runs.
class ResidencyOctree {
 public:
  /// Bytes of device storage per node for `slots` visible slots.
  static constexpr std::size_t bytes_per_node(std::uint32_t slots) noexcept {
    return std::size_t(slots) * 4u * sizeof(std::uint32_t);
  }

  /// Throws Error(invalid_argument) naming "slots" (0, above kMaxChannels, or storage beyond
  /// 2^32 words), "layout" (extent differs from the hierarchy's) or "query" (empty), and
  /// Error(out_of_memory) when the storage cannot be allocated. Every slot starts with
  /// default_range(volume type) and nothing resident.
  ResidencyOctree(const BrickHierarchy& hierarchy, OctreeLayout layout, std::uint32_t slots,
                  ResidencyQuery query);

  const BrickHierarchy& hierarchy() const noexcept { return hierarchy_; }
  const OctreeLayout& layout() const noexcept { return layout_; }
  std::uint32_t slot_count() const noexcept { return slots_; }
  const ValueRange& slot_range(std::uint32_t slot) const { return ranges_.at(slot); }

  /// Maps a slot to a (new) channel with value range `range`: clears that slot's residency and
  /// metadata in every node. Bricks of the old channel must no longer be reported resident.
  /// Throws Error naming "slot" or "range" (empty or not finite).
  void remap_slot(std::uint32_t slot, const ValueRange& range);

  /// A brick became resident: overlapping leaves get bit `level`, then ancestors by OR, depth by
  /// depth, stopping at the first depth where no word changed. Throws Error(out_of_range) for a
  /// slot, level or brick outside the hierarchy.
  void brick_added(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick);
  /// A brick was evicted (the query must already report it non-resident): each overlapping leaf
  /// clears bit `level` unless another resident brick of that level and slot overlaps it; parents
  /// are recomputed by OR while anything changes.
  void brick_evicted(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick);

  /// Conservative metadata of the level-0 voxels a node's samples read (a source's region_meta
  /// answer for OctreeLayout::sampling_support(node), occupancy over this slot's range). Replaces
  /// earlier data supplied for the same node and discards its coarse-brick estimate; ancestors are
  /// updated while they change. Throws Error(out_of_range) for a bad slot or node or a node outside
  /// the volume.
  void node_metadata(std::uint32_t slot, std::uint64_t node, const RegionMeta& meta);

  /// Metadata from a brick's voxels (`voxels` as written by BrickSource::read_brick, padded, of
  /// the volume's type). Level 0: every leaf fully inside the brick whose sampling support the
  /// padded brick holds (a halo of at least one voxel) gets exact (VALID) metadata of the
  /// support's voxels; where the node also has conservative data (node_metadata) the record is
  /// the intersection of both, so a resident level-0 brick tightens a coarse region answer.
  /// Level l > 0: every node fully inside the brick at the deepest depth whose nodes are no
  /// smaller than a level-l voxel gets an APPROX estimate from the averaged voxels over it. An
  /// estimate replaces one from the same or a coarser level and is ignored once the node has
  /// conservative data. Risk: averaging hides thin peaks, so APPROX may be narrower than the truth
  /// and culling with it may drop fine features until level-0 data arrives.
  /// Throws Error naming "voxels" for a wrong buffer size, or Error(out_of_range).
  void metadata_from_brick(std::uint32_t slot, std::uint32_t level, glm::uvec3 brick,
                           std::span<const std::byte> voxels);
  /// metadata_from_brick for a constant level-0 brick (BrickMeta::constant over its padded
  /// voxels, which the loader does not keep): its leaves get the exact record of that one value.
  /// Throws Error naming "meta" for a brick that is not constant, or Error(out_of_range).
  void metadata_from_constant_brick(std::uint32_t slot, glm::uvec3 brick, const BrickMeta& meta);
  /// Exact (VALID) leaf records computed elsewhere from level-0 brick `brick` (scan_leaves or
  /// scan_constant_leaves with this octree's layout and the slot's range, e.g. on a loader
  /// thread): stored as metadata_from_brick stores its own scan, then ancestors are updated.
  /// Throws Error(out_of_range) for a bad slot or brick, or a record whose node is not a leaf
  /// of that brick (nothing is stored then).
  void leaf_metadata(std::uint32_t slot, glm::uvec3 brick, std::span<const LeafScan> leaves);

  /// Device-ready storage: node-major records of 4 words (kernel/octree_node.glsl.h).
  std::span<const std::uint32_t> words() const noexcept { return words_; }
  /// One word of a record: which = RESOCT_NODE_RESIDENCY ... RESOCT_NODE_FLAGS.
  std::uint32_t word(std::uint64_t node, std::uint32_t slot, std::uint32_t which) const;

  /// Changed words since the previous call (deduplicated), then starts a new list.
  OctreeDeltas take_deltas();

  const OctreeUpdateStats& stats() const noexcept { return stats_; }
  void reset_stats() noexcept { stats_ = {}; }

  /// Recomputes every record by brute force: residency from the query over all bricks of all
  /// levels and slots, metadata from everything supplied so far, and checks that parents cover
  /// their children. Returns a description of the first mismatch (node, depth, slot, word,
  /// stored and expected values), or nothing. Cost: O(bricks * overlapped nodes + nodes).
  std::optional<std::string> check_invariants() const;

 private:
  /// What was supplied for one (node, slot) itself, quantized.
  struct OwnMeta {
    bool has_direct = false;
    bool has_exact = false;
    bool has_approx = false;
    std::uint32_t direct_minmax = 0, direct_occupancy = 0;
    std::uint32_t exact_minmax = 0, exact_occupancy = 0;
    std::uint32_t approx_minmax = 0, approx_occupancy = 0, approx_level = 0;
  };
  struct Record {
    std::uint32_t minmax = 0, occupancy = 0, flags = 0;
    friend bool operator==(const Record&, const Record&) = default;
  };

  std::size_t base(std::uint64_t node, std::uint32_t slot) const noexcept {
    return (std::size_t(node) * slots_ + slot) * 4u;
  }
  void set_word(std::size_t index, std::uint32_t value);
  void check_slot(std::uint32_t slot) const;
  void check_brick(std::uint32_t level, glm::uvec3 brick) const;
  /// The sampling support of a leaf of a level-0 brick's core when the padded brick holds it,
  /// else an empty box.
  bool other_brick_resident(std::uint32_t slot, std::uint32_t level, glm::uvec3 evicted,
                            const Box3& leaf_box);
  /// The metadata rule: a record from the node's own data and its children's stored records.
  Record compute_record(std::uint32_t d, std::uint64_t node, glm::uvec3 coord, std::uint32_t slot,
                        std::span<const std::uint32_t> storage) const;
  /// Recomputes the records in `range` at depth d, then their ancestors depth by depth while any
  /// record changes.
  void propagate_metadata(std::uint32_t slot, std::uint32_t d, NodeCoordRange range);
  OwnMeta& own(std::uint64_t node, std::uint32_t slot) {
    return own_[std::uint64_t(node) * slots_ + slot];
  }

  BrickHierarchy hierarchy_;
  OctreeLayout layout_;
  std::uint32_t slots_ = 0;
  ResidencyQuery query_;
  std::vector<ValueRange> ranges_;
  std::vector<std::uint32_t> words_;
  std::unordered_map<std::uint64_t, OwnMeta> own_;  // key node * slots + slot; visited only

  std::vector<std::uint64_t> dirty_bits_;
  std::vector<std::uint32_t> dirty_list_;
  bool dirty_full_ = false;
  OctreeUpdateStats stats_;
};

}  // namespace resoct
