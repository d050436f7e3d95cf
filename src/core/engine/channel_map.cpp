#include "resoct/engine/channel_map.hpp"

#include <string>

#include "resoct/base/error.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

ChannelMap::ChannelMap(std::uint32_t slots, std::uint32_t channels) : channels_(channels) {
  if (slots == 0) throw invalid_parameter("slots", "at least one visible channel slot is needed");
  if (channels == 0 || channels > kMaxChannels) {
    throw invalid_parameter("channels", "must be 1.." + std::to_string(kMaxChannels) + ", got " +
                                            std::to_string(channels));
  }
  slot_channel_.assign(slots, -1);
  assigned_at_.assign(slots, 0);
  channel_slot_.assign(channels, -1);
}

void ChannelMap::check_slot(std::uint32_t slot) const {
  if (slot >= slot_channel_.size()) {
    throw Error(ErrorCode::out_of_range, "slot " + std::to_string(slot) + " out of range (" +
                                             std::to_string(slot_channel_.size()) + " slots)");
  }
}

std::optional<std::uint32_t> ChannelMap::channel(std::uint32_t slot) const {
  check_slot(slot);
  if (slot_channel_[slot] < 0) return std::nullopt;
  return std::uint32_t(slot_channel_[slot]);
}

std::optional<std::uint32_t> ChannelMap::slot_of(std::uint32_t channel) const {
  if (channel >= channels_ || channel_slot_[channel] < 0) return std::nullopt;
  return std::uint32_t(channel_slot_[channel]);
}

std::uint64_t ChannelMap::assigned_at(std::uint32_t slot) const {
  check_slot(slot);
  return assigned_at_[slot];
}

SlotRemap ChannelMap::assign(std::uint32_t slot, std::optional<std::uint32_t> channel,
                             PageTable& table) {
  check_slot(slot);
  if (table.slot_count() != slot_count()) {
    throw invalid_parameter("table", "page table has " + std::to_string(table.slot_count()) +
                                         " slots, channel map " + std::to_string(slot_count()));
  }
  const std::int32_t next = channel ? std::int32_t(*channel) : -1;
  if (channel) {
    if (*channel >= channels_) {
      throw invalid_parameter("channel", std::to_string(*channel) + " out of range (" +
                                             std::to_string(channels_) + " channels)");
    }
    const std::int32_t holder = channel_slot_[*channel];
    if (holder >= 0 && std::uint32_t(holder) != slot) {
      throw invalid_parameter("channel", "channel " + std::to_string(*channel) +
                                             " is already shown in slot " + std::to_string(holder));
    }
  }
  SlotRemap out;
  if (slot_channel_[slot] == next) {
    out.epoch = assigned_at_[slot];
    return out;
  }
  if (slot_channel_[slot] >= 0) channel_slot_[std::size_t(slot_channel_[slot])] = -1;
  slot_channel_[slot] = next;
  if (next >= 0) channel_slot_[std::size_t(next)] = std::int32_t(slot);
  assigned_at_[slot] = ++epoch_;
  out.epoch = epoch_;
  out.released_cache_slots = table.clear_slot(slot);
  return out;
}

std::optional<BrickKey> ChannelMap::resolve(std::uint32_t device_key, std::uint64_t epoch,
                                            const PageTable& table) const {
  if (epoch > epoch_) {
    throw Error(ErrorCode::out_of_range, "request epoch " + std::to_string(epoch) +
                                             " is newer than the channel map's " +
                                             std::to_string(epoch_));
  }
  const std::optional<PageAddress> a = table.decode_device_key(device_key);
  if (!a || a->slot >= slot_count()) return std::nullopt;
  if (assigned_at_[a->slot] > epoch || slot_channel_[a->slot] < 0) return std::nullopt;
  return BrickKey(a->level, std::uint32_t(slot_channel_[a->slot]), a->brick);
}

ResolvedRequests ChannelMap::resolve(std::span<const Request> requests, std::uint64_t epoch,
                                     const PageTable& table) const {
  ResolvedRequests out;
  out.bricks.reserve(requests.size());
  out.hits.reserve(requests.size());
  for (const Request& r : requests) {
    if (const std::optional<BlockMiss> miss = table.decode_block_miss(r.key)) {
      if (miss->slot < slot_count() && assigned_at_[miss->slot] <= epoch &&
          slot_channel_[miss->slot] >= 0) {
        out.block_misses.push_back(miss->directory_index);
      } else {
        ++out.stale;
      }
      continue;
    }
    if (const std::optional<BrickKey> key = resolve(r.key, epoch, table)) {
      out.bricks.push_back(*key);
      out.hits.push_back(r.hits);
    } else {
      ++out.stale;
    }
  }
  return out;
}

std::optional<PageAddress> ChannelMap::address_of(BrickKey key) const {
  const std::optional<std::uint32_t> s = slot_of(key.channel());
  if (!s) return std::nullopt;
  return PageAddress{*s, key.level(), key.brick()};
}

}  // namespace resoct
