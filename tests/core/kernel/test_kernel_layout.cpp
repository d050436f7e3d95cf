// The GPU-visible record layouts (page entry, request key) decode what they encode at the limits,
// and the constants agree with each other and with the host structures built on them.
#include <gtest/gtest.h>

#include <random>

#include "resoct/engine/brick_cache.hpp"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"
#include "resoct/engine/page_table.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
namespace k = resoct::kernel;

static_assert(k::RESOCT_PAGE_PAYLOAD_MASK == (1u << k::RESOCT_PAGE_STATE_SHIFT) - 1u);
// MAPPED: the cache slot below the error code, which ends where the payload does.
static_assert(k::RESOCT_PAGE_MAX_CACHE_SLOT == (1u << k::RESOCT_PAGE_ERROR_SHIFT) - 1u);
static_assert(((k::RESOCT_PAGE_ERROR_MAX << k::RESOCT_PAGE_ERROR_SHIFT) |
               k::RESOCT_PAGE_MAX_CACHE_SLOT) == k::RESOCT_PAGE_PAYLOAD_MASK);
static_assert(k::RESOCT_PAGE_UNMAPPED_WORD == 0u, "a zero-filled buffer must be an unmapped table");
static_assert(k::RESOCT_PAGE_EMPTY_WORD == k::RESOCT_PAGE_STATE_EMPTY
                                               << k::RESOCT_PAGE_STATE_SHIFT);
static_assert(k::RESOCT_PAGE_STATE_HOMOGENEOUS == 3u &&
              (3u << k::RESOCT_PAGE_STATE_SHIFT) >> k::RESOCT_PAGE_STATE_SHIFT == 3u);
// Brick keys: 19 bits of pool block above 12 bits of in-block index, bit 31 clear.
static_assert(k::RESOCT_REQUEST_IN_BLOCK_MASK + 1u == k::RESOCT_PAGE_BLOCK_ENTRIES);
static_assert(k::RESOCT_PAGE_BLOCK_ENTRIES == 1u << (3u * k::RESOCT_PAGE_BLOCK_LOG2));
static_assert(k::RESOCT_PAGE_BLOCK_ENTRIES == 1u << k::RESOCT_PAGE_BLOCK_ENTRIES_LOG2);
static_assert(k::RESOCT_REQUEST_MAX_POOL_BLOCKS == k::RESOCT_REQUEST_POOL_BLOCK_MASK + 1u);
static_assert((k::RESOCT_REQUEST_POOL_BLOCK_MASK << k::RESOCT_REQUEST_IN_BLOCK_BITS |
               k::RESOCT_REQUEST_IN_BLOCK_MASK) == 0x7FFFFFFFu);
static_assert(k::RESOCT_REQUEST_MAX_DIRECTORY == ~k::RESOCT_REQUEST_BLOCK_MISS_BIT);
static_assert(sizeof(k::uint) == 4u);
// Deltas go to device buffers as (index, value) word pairs.
static_assert(sizeof(PageDelta) == 8u && offsetof(PageDelta, value) == 4u);

TEST(KernelLayout, PageEntryRoundTripsAtLimits) {
  for (std::uint32_t slot :
       {0u, 1u, 12345u, k::RESOCT_PAGE_MAX_CACHE_SLOT - 1u, k::RESOCT_PAGE_MAX_CACHE_SLOT}) {
    const std::uint32_t e = k::resoct_page_encode_mapped(slot);
    EXPECT_EQ(k::resoct_page_state(e), k::RESOCT_PAGE_STATE_MAPPED);
    EXPECT_TRUE(k::resoct_page_is_mapped(e));
    EXPECT_FALSE(k::resoct_page_is_constant(e));
    EXPECT_EQ(k::resoct_page_cache_slot(e), slot);
    EXPECT_EQ(k::resoct_page_payload(e), slot);
  }
  for (std::uint32_t v : {0u, 1u, 32768u, 65534u, 65535u}) {
    const std::uint32_t e = k::resoct_page_encode_homogeneous(v);
    EXPECT_EQ(k::resoct_page_state(e), k::RESOCT_PAGE_STATE_HOMOGENEOUS);
    EXPECT_TRUE(k::resoct_page_is_constant(e));
    EXPECT_FALSE(k::resoct_page_is_mapped(e));
    EXPECT_EQ(k::resoct_page_payload(e), v);
    EXPECT_FLOAT_EQ(k::resoct_page_homogeneous_value(e), float(v) / 65535.0f);
  }
  EXPECT_EQ(k::resoct_page_state(k::RESOCT_PAGE_UNMAPPED_WORD), k::RESOCT_PAGE_STATE_UNMAPPED);
  EXPECT_FALSE(k::resoct_page_is_constant(k::RESOCT_PAGE_UNMAPPED_WORD));
  EXPECT_EQ(k::resoct_page_state(k::RESOCT_PAGE_EMPTY_WORD), k::RESOCT_PAGE_STATE_EMPTY);
  EXPECT_TRUE(k::resoct_page_is_constant(k::RESOCT_PAGE_EMPTY_WORD));
  EXPECT_EQ(k::resoct_page_homogeneous_value(k::RESOCT_PAGE_EMPTY_WORD), 0.0f);
  // Error codes ride on MAPPED and HOMOGENEOUS entries without changing slot, value or state.
  for (std::uint32_t code = 0; code <= k::RESOCT_PAGE_ERROR_MAX; ++code) {
    for (std::uint32_t slot : {0u, 777u, k::RESOCT_PAGE_MAX_CACHE_SLOT}) {
      const std::uint32_t e = k::resoct_page_with_error(k::resoct_page_encode_mapped(slot), code);
      EXPECT_EQ(k::resoct_page_state(e), k::RESOCT_PAGE_STATE_MAPPED);
      EXPECT_EQ(k::resoct_page_cache_slot(e), slot);
      EXPECT_EQ(k::resoct_page_error_code(e), code);
    }
    for (std::uint32_t v : {0u, 32768u, 65535u}) {
      const std::uint32_t e = k::resoct_page_with_error(k::resoct_page_encode_homogeneous(v), code);
      EXPECT_EQ(k::resoct_page_state(e), k::RESOCT_PAGE_STATE_HOMOGENEOUS);
      EXPECT_FLOAT_EQ(k::resoct_page_homogeneous_value(e), float(v) / 65535.0f);
      EXPECT_EQ(k::resoct_page_error_code(e), code);
    }
  }
  EXPECT_EQ(k::resoct_page_error_code(k::RESOCT_PAGE_EMPTY_WORD), 0u);
  EXPECT_EQ(k::resoct_page_error_code(k::RESOCT_PAGE_EMPTY_NAN_WORD), 0u);
  EXPECT_EQ(k::resoct_page_error_code(k::RESOCT_PAGE_UNMAPPED_WORD), 0u);
  // The four states are distinct words even with payload 0.
  EXPECT_NE(k::resoct_page_encode_mapped(0), k::RESOCT_PAGE_UNMAPPED_WORD);
  EXPECT_NE(k::resoct_page_encode_homogeneous(0), k::RESOCT_PAGE_EMPTY_WORD);
}

TEST(KernelLayout, RequestKeyRoundTripsAtLimits) {
  for (std::uint32_t b : {1u, 2u, 0x1234u, k::RESOCT_REQUEST_MAX_POOL_BLOCKS - 1u}) {
    for (std::uint32_t in : {0u, 1u, 0xABCu, k::RESOCT_PAGE_BLOCK_ENTRIES - 1u}) {
      const std::uint32_t key = k::resoct_request_key_brick(b, in);
      EXPECT_FALSE(k::resoct_request_key_is_block_miss(key));
      EXPECT_EQ(k::resoct_request_key_pool_block(key), b);
      EXPECT_EQ(k::resoct_request_key_in_block(key), in);
      EXPECT_NE(key, k::RESOCT_REQUEST_KEY_NONE);
    }
  }
  for (std::uint32_t d : {0u, 1u, 0x00ABCDEFu, k::RESOCT_REQUEST_MAX_DIRECTORY - 1u}) {
    const std::uint32_t key = k::resoct_request_key_block_miss(d);
    EXPECT_TRUE(k::resoct_request_key_is_block_miss(key));
    EXPECT_EQ(k::resoct_request_key_directory(key), d);
    EXPECT_NE(key, k::RESOCT_REQUEST_KEY_NONE);
  }
  EXPECT_EQ(k::resoct_request_table_id(3u, 5u, 9u), 3u * 9u + 5u);
  std::mt19937 rng(7);
  for (std::uint32_t log2 : {0u, 1u, 10u, 20u, 28u}) {
    for (int i = 0; i < 1000; ++i) {
      EXPECT_LT(k::resoct_request_key_hash(std::uint32_t(rng()), log2), 1ull << log2);
    }
  }
}

TEST(KernelLayout, PageLocalIndexMatchesHierarchyLinearIndex) {
  VolumeDesc v;
  v.extent = {40, 33, 17};
  const BrickHierarchy h(v, BrickLayout{glm::uvec3(8), 1});
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const LevelInfo& li = h.level(l);
    for (std::uint32_t z = 0; z < li.bricks.z; ++z)
      for (std::uint32_t y = 0; y < li.bricks.y; ++y)
        for (std::uint32_t x = 0; x < li.bricks.x; ++x) {
          const glm::uvec3 b(x, y, z);
          EXPECT_EQ(std::uint64_t(k::resoct_page_local_index(b, li.bricks)) + li.first_brick,
                    h.linear_index(l, b));
        }
  }
}

TEST(KernelLayout, HostKeysAndEntriesUseTheKernelEncoding) {
  VolumeDesc v;
  v.extent = {795, 3, 1};
  v.channels = 3;
  const BrickHierarchy h(v, BrickLayout{glm::uvec3(8), 1});
  PageTable pt(h, 3, 16);
  const PageAddress a{2, 1, glm::uvec3(17, 0, 0)};
  // Level 1 is 50 bricks wide: 4 blocks; brick 17 lies in block 1 at x = 1.
  const std::uint32_t d = pt.directory_offsets()[2u * h.level_count() + 1u] + 1u;
  EXPECT_EQ(pt.directory_index(a), d);
  EXPECT_EQ(pt.device_key(a), k::resoct_request_key_block_miss(d));
  pt.set_mapped(a, k::RESOCT_PAGE_MAX_CACHE_SLOT);
  EXPECT_EQ(pt.entry(a), k::resoct_page_encode_mapped(k::RESOCT_PAGE_MAX_CACHE_SLOT));
  const std::uint32_t block = pt.directory()[d];
  EXPECT_NE(block, 0u);
  const std::uint32_t key = pt.device_key(a);
  EXPECT_EQ(k::resoct_request_key_pool_block(key), block);
  EXPECT_EQ(k::resoct_request_key_in_block(key), 1u);
  EXPECT_EQ(pt.pool()[block * k::RESOCT_PAGE_BLOCK_ENTRIES + 1u], pt.entry(a));
  // The error code goes into the entry beside the slot; a slot or code too large is refused.
  pt.set_mapped(a, 9u, 11u);
  EXPECT_EQ(pt.entry(a), k::resoct_page_with_error(k::resoct_page_encode_mapped(9u), 11u));
  EXPECT_RESOCT_ERROR(pt.set_mapped(a, k::RESOCT_PAGE_MAX_CACHE_SLOT + 1u),
                      ErrorCode::invalid_argument, "cache_slot");
  EXPECT_RESOCT_ERROR(pt.set_mapped(a, 9u, 16u), ErrorCode::invalid_argument, "error_code");
  pt.set_homogeneous(a, 0.25, ValueRange{0.0, 1.0}, 3u);
  EXPECT_EQ(k::resoct_page_error_code(pt.entry(a)), 3u);
  EXPECT_EQ(pt.homogeneous_value(a), 0.25);
  // A cache cannot hand out a slot the entry cannot hold: 2^26 slots is its limit (checked before
  // anything is allocated).
  const BrickLayout small{glm::uvec3(4), 0};
  const std::uint64_t slot_bytes = small.padded_voxels();
  EXPECT_RESOCT_ERROR(
      BrickCache(small, VoxelType::u8, slot_bytes * (k::RESOCT_PAGE_MAX_CACHE_SLOT + 2ull)),
      ErrorCode::invalid_argument, "capacity_bytes");
}
