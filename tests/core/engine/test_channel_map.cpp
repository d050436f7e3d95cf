// Channel map: remapping at run time, epochs, and dropping keys recorded under an old mapping.
#include <gtest/gtest.h>

#include <algorithm>

#include "resoct/engine/channel_map.hpp"
#include "resoct/kernel/request_key.glsl.h"
#include "support/expect_error.hpp"

using namespace resoct;
namespace k = resoct::kernel;

namespace {
BrickHierarchy hierarchy(std::uint32_t channels) {
  VolumeDesc v;
  v.extent = {40, 33, 17};
  v.channels = channels;
  return BrickHierarchy(v, BrickLayout{glm::uvec3(8), 1});
}
}  // namespace

TEST(ChannelMap, KeysFromBeforeARemapOfTheirSlotAreDropped) {
  const BrickHierarchy h = hierarchy(6);
  PageTable pt(h, 2, 64);
  ChannelMap cm(2, 6);
  EXPECT_EQ(cm.epoch(), 0u);
  EXPECT_FALSE(cm.channel(0).has_value());
  cm.assign(0, 4, pt);
  cm.assign(1, 2, pt);
  const std::uint64_t e1 = cm.epoch();
  EXPECT_EQ(e1, 2u);
  const PageAddress a0{0, 1, {2, 1, 0}}, a1{1, 0, {4, 4, 2}};
  // Brick keys exist once the bricks' blocks are allocated.
  pt.allocate_block(pt.directory_index(a0));
  pt.allocate_block(pt.directory_index(a1));
  const std::uint32_t k0 = pt.device_key(a0), k1 = pt.device_key(a1);
  EXPECT_EQ(cm.resolve(k0, e1, pt), BrickKey(1, 4, {2, 1, 0}));
  EXPECT_EQ(cm.resolve(k1, e1, pt), BrickKey(0, 2, {4, 4, 2}));
  // Slot 0 now shows channel 5: its old keys are stale, slot 1's survive.
  const SlotRemap r = cm.assign(0, 5, pt);
  EXPECT_EQ(r.epoch, e1 + 1);
  EXPECT_EQ(cm.epoch(), e1 + 1);
  EXPECT_FALSE(cm.resolve(k0, e1, pt).has_value());
  EXPECT_EQ(cm.resolve(k1, e1, pt), BrickKey(0, 2, {4, 4, 2}));
  // The remap freed slot 0's blocks; a key recorded under the new mapping resolves to it.
  EXPECT_FALSE(cm.resolve(k0, cm.epoch(), pt).has_value());
  pt.allocate_block(pt.directory_index(a0));
  EXPECT_EQ(cm.resolve(pt.device_key(a0), cm.epoch(), pt), BrickKey(1, 5, {2, 1, 0}));
  // Keys recorded before the slot was ever assigned are stale as well.
  EXPECT_FALSE(cm.resolve(k1, 1, pt).has_value());
  // Unassigned slot: nothing resolves.
  cm.assign(1, std::nullopt, pt);
  EXPECT_FALSE(cm.resolve(k1, cm.epoch(), pt).has_value());
  EXPECT_FALSE(cm.resolve(k::RESOCT_REQUEST_KEY_NONE, cm.epoch(), pt).has_value());
  EXPECT_RESOCT_ERROR(cm.resolve(k0, cm.epoch() + 1, pt), ErrorCode::out_of_range, "epoch");
}

TEST(ChannelMap, RemapClearsTheSlotsTablesAndReportsCacheSlots) {
  const BrickHierarchy h = hierarchy(3);
  PageTable pt(h, 2, 64);
  ChannelMap cm(2, 3);
  cm.assign(0, 0, pt);
  cm.assign(1, 1, pt);
  pt.set_mapped({0, 0, {1, 1, 1}}, 10);
  pt.set_mapped({0, 2, {0, 0, 0}}, 11);
  pt.set_empty({0, 1, {0, 0, 0}});
  pt.set_mapped({1, 0, {1, 1, 1}}, 12);
  pt.take_deltas();
  SlotRemap r = cm.assign(0, 2, pt);
  std::sort(r.released_cache_slots.begin(), r.released_cache_slots.end());
  EXPECT_EQ(r.released_cache_slots, (std::vector<std::uint32_t>{10, 11}));
  EXPECT_EQ(pt.entry({0, 0, {1, 1, 1}}), k::RESOCT_PAGE_UNMAPPED_WORD);
  EXPECT_EQ(pt.entry({0, 1, {0, 0, 0}}), k::RESOCT_PAGE_UNMAPPED_WORD);
  EXPECT_EQ(pt.entry({1, 0, {1, 1, 1}}), k::resoct_page_encode_mapped(12));
  const PageTableDeltas d = pt.take_deltas();
  EXPECT_EQ(d.pool.size(), 3u);       // the three entries of slot 0
  EXPECT_EQ(d.directory.size(), 3u);  // and their blocks (one per level) freed
  for (const PageDelta& x : d.directory) EXPECT_EQ(x.value, 0u);
  // Re-assigning the same channel changes nothing.
  const std::uint64_t e = cm.epoch();
  pt.set_mapped({0, 0, {0, 0, 0}}, 13);
  r = cm.assign(0, 2, pt);
  EXPECT_TRUE(r.released_cache_slots.empty());
  EXPECT_EQ(cm.epoch(), e);
  EXPECT_EQ(pt.entry({0, 0, {0, 0, 0}}), k::resoct_page_encode_mapped(13));
}

TEST(ChannelMap, LookupsBothWaysAndErrors) {
  const BrickHierarchy h = hierarchy(4);
  PageTable pt(h, 2, 64);
  ChannelMap cm(2, 4);
  cm.assign(1, 3, pt);
  EXPECT_EQ(cm.slot_of(3), 1u);
  EXPECT_FALSE(cm.slot_of(0).has_value());
  EXPECT_FALSE(cm.slot_of(99).has_value());
  EXPECT_EQ(cm.address_of(BrickKey(2, 3, {1, 0, 0})), (PageAddress{1, 2, {1, 0, 0}}));
  EXPECT_FALSE(cm.address_of(BrickKey(2, 0, {1, 0, 0})).has_value());
  EXPECT_RESOCT_ERROR(cm.assign(0, 3, pt), ErrorCode::invalid_argument, "already shown in slot 1");
  EXPECT_RESOCT_ERROR(cm.assign(0, 4, pt), ErrorCode::invalid_argument, "channel");
  EXPECT_RESOCT_ERROR(cm.assign(2, 0, pt), ErrorCode::out_of_range, "slot");
  PageTable other(h, 3, 64);
  EXPECT_RESOCT_ERROR(cm.assign(0, 0, other), ErrorCode::invalid_argument, "table");
  EXPECT_RESOCT_ERROR(ChannelMap(0, 4), ErrorCode::invalid_argument, "slots");
  EXPECT_RESOCT_ERROR(ChannelMap(2, 0), ErrorCode::invalid_argument, "channels");
  EXPECT_RESOCT_ERROR(ChannelMap(2, 257), ErrorCode::invalid_argument, "channels");
  // Moving a channel: free it first, then show it elsewhere.
  cm.assign(1, std::nullopt, pt);
  cm.assign(0, 3, pt);
  EXPECT_EQ(cm.slot_of(3), 0u);
  EXPECT_EQ(cm.assigned_at(0), cm.epoch());
}

TEST(ChannelMap, ResolvesADrainedBatchAndCountsStaleRequests) {
  const BrickHierarchy h = hierarchy(4);
  PageTable pt(h, 2, 64);
  ChannelMap cm(2, 4);
  cm.assign(0, 1, pt);
  cm.assign(1, 3, pt);
  const std::uint64_t recorded = cm.epoch();
  RequestSet rs(64);
  const PageAddress a{0, 0, {1, 2, 0}}, b{1, 2, {0, 1, 0}}, c{0, 1, {2, 0, 1}};
  const PageAddress miss0{0, 3, {0, 0, 0}}, miss1{1, 3, {0, 0, 0}};
  for (const PageAddress& x : {a, b, c}) pt.allocate_block(pt.directory_index(x));
  rs.insert(pt.device_key(a), 5);
  rs.insert(pt.device_key(b), 9);
  rs.insert(pt.device_key(c), 2);
  rs.insert(pt.device_key(miss0), 1);  // block misses: slot 0 valid, slot 1 remapped below
  rs.insert(pt.device_key(miss1), 1);
  rs.insert(k::resoct_request_key_brick(pt.pool_block_count(), 0));  // garbage from the device
  rs.insert(k::resoct_request_key_block_miss(0x7FFFFFF0u));          // garbage as well
  cm.assign(1, 2, pt);  // slot 1 remapped after recording
  const RequestBatch batch = rs.drain([&](std::uint32_t key) {
    const auto d = pt.decode_device_key(key);
    return d ? d->level : 0u;
  });
  const ResolvedRequests r = cm.resolve(batch.requests, recorded, pt);
  // b (slot 1) is stale; the garbage key is stale; c (level 1) comes before a (level 0).
  EXPECT_EQ(r.bricks,
            (std::vector<BrickKey>{BrickKey(1, 1, {2, 0, 1}), BrickKey(0, 1, {1, 2, 0})}));
  EXPECT_EQ(r.hits, (std::vector<std::uint32_t>{2, 5}));
  EXPECT_EQ(r.block_misses, (std::vector<std::uint32_t>{pt.directory_index(miss0)}));
  EXPECT_EQ(r.stale, 4u);
}
