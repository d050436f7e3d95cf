#pragma once
/// \file
/// Which dataset channel each visible slot shows, changing at run time, with an epoch counter so
/// that device request keys recorded under an old mapping are recognised and dropped.

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "resoct/volume/brick_key.hpp"
#include "resoct/engine/page_table.hpp"
#include "resoct/engine/request_set.hpp"

namespace resoct {

/// Outcome of assigning a channel to a slot.
struct SlotRemap {
  std::uint64_t epoch = 0;  ///< the epoch from which the new mapping holds
  /// Cache slots whose bricks belonged to the slot's old channel: release them in the cache.
  std::vector<std::uint32_t> released_cache_slots;
};

/// Drained brick requests translated to global bricks, in the order they were given.
struct ResolvedRequests {
  std::vector<BrickKey> bricks;
  std::vector<std::uint32_t> hits;  ///< parallel to bricks
  std::uint64_t stale = 0;          ///< requests dropped: remapped or unassigned slot, bad key
  /// Directory indices of unallocated page-table blocks reported (block-miss keys) for valid
  /// slots: allocate them (PageTable::allocate_block) after everything is resolved.
  std::vector<std::uint32_t> block_misses;
};

/// Slot <-> channel map. Epoch 0 is the initial (all slots unassigned) state; every assign()
/// starts a new epoch. Requests carry the epoch under which the frame that recorded them ran
/// (epoch() at that time). A request for slot s is valid iff s was last assigned at or before
/// that epoch, so late answers for a remapped slot are dropped, and requests for untouched slots
/// survive remaps of other slots.
/// A channel occupies at most one slot. Thread-safety: none; owned by the frame loop.
class ChannelMap {
 public:
  /// `channels` is the dataset's channel count; throws Error(invalid_argument) naming "slots" or
  /// "channels" when either is 0 or channels exceeds BrickKey's 256.
  ChannelMap(std::uint32_t slots, std::uint32_t channels);

  std::uint32_t slot_count() const noexcept { return std::uint32_t(slot_channel_.size()); }
  std::uint64_t epoch() const noexcept { return epoch_; }
  /// Channel shown in a slot, nullopt when unassigned.
  std::optional<std::uint32_t> channel(std::uint32_t slot) const;
  /// Slot showing a channel, nullopt when the channel is not visible.
  std::optional<std::uint32_t> slot_of(std::uint32_t channel) const;
  /// Epoch at which the slot got its current mapping.
  std::uint64_t assigned_at(std::uint32_t slot) const;

  /// Shows `channel` in `slot` (nullopt clears it). A change clears the slot's page tables
  /// (entries become UNMAPPED, deltas recorded) and starts a new epoch. Assigning the channel the
  /// slot already shows changes nothing. Throws Error(invalid_argument) when the channel is
  /// already shown in another slot or out of range, or when the table has another slot count.
  SlotRemap assign(std::uint32_t slot, std::optional<std::uint32_t> channel, PageTable& table);

  /// The global brick of a device key recorded under `epoch`, or nullopt when the key is invalid,
  /// its slot was remapped after `epoch`, or the slot is unassigned. Throws Error(out_of_range)
  /// for an epoch from the future (a caller bug, not device data).
  std::optional<BrickKey> resolve(std::uint32_t device_key, std::uint64_t epoch,
                                  const PageTable& table) const;
  /// resolve() for a frame's drained brick requests, keeping their (priority) order; block-miss
  /// keys of valid slots go to `block_misses` instead.
  ResolvedRequests resolve(std::span<const Request> requests, std::uint64_t epoch,
                           const PageTable& table) const;
  /// The page-table address of a global brick, nullopt when its channel is not visible.
  std::optional<PageAddress> address_of(BrickKey key) const;

 private:
  void check_slot(std::uint32_t slot) const;

  std::uint32_t channels_;
  std::uint64_t epoch_ = 0;
  std::vector<std::int32_t> slot_channel_;  // -1: unassigned
  std::vector<std::uint64_t> assigned_at_;
  std::vector<std::int32_t> channel_slot_;  // -1: not visible
};

}  // namespace resoct
