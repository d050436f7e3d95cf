// The sparse two-level page table against a brute-force std::map model: random set / clear /
// allocate / clear_slot sequences over partial blocks and block borders with a pool small enough
// to be exhausted, checking entries, the reclaim rule (least recently written block without a
// MAPPED entry, whole blocks only), the device mirror built from deltas, device-key round trips
// and hostile keys; and a 65536^3 hierarchy whose host memory stays bounded.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "resoct/kernel/request_key.glsl.h"
#include "resoct/engine/page_table.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
namespace k = resoct::kernel;

namespace {

BrickHierarchy make(glm::u64vec3 extent, glm::uvec3 brick) {
  VolumeDesc v;
  v.extent = extent;
  return BrickHierarchy(v, BrickLayout{brick, 1});
}

using Addr = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t,
                        std::uint32_t>;  // slot, level, x, y, z

Addr key_of(const PageAddress& a) {
  return {a.slot, a.level, a.brick.x, a.brick.y, a.brick.z};
}
PageAddress addr_of(const Addr& t) {
  return {std::get<0>(t), std::get<1>(t), {std::get<2>(t), std::get<3>(t), std::get<4>(t)}};
}

// Brute-force block identity: (slot, level, brick / 16).
using BlockId =
    std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>;
BlockId block_of(const PageAddress& a) {
  return {a.slot, a.level, a.brick.x / 16u, a.brick.y / 16u, a.brick.z / 16u};
}

struct Mirror {
  std::vector<std::uint32_t> pool, dir;
  void apply(const PageTableDeltas& d) {
    for (const PageDelta& x : d.pool) pool.at(x.index) = x.value;
    for (const PageDelta& x : d.directory) dir.at(x.index) = x.value;
  }
  std::uint32_t entry(const PageTable& pt, const PageAddress& a) const {
    return pool.at(std::size_t(dir.at(pt.directory_index(a))) * 4096u +
                   k::resoct_page_in_block_index(a.brick));
  }
};

void run_model(std::uint32_t seed, std::uint32_t max_blocks) {
  // Level 0 is 40 x 21 x 35 bricks: 3 x 2 x 3 blocks, partial on every axis.
  const BrickHierarchy h = make({320, 168, 280}, glm::uvec3(8));
  const std::uint32_t slots = 2;
  PageTable pt(h, slots, max_blocks);
  Mirror dev{std::vector<std::uint32_t>(std::size_t(pt.pool_block_count()) * 4096u, 0u),
             pt.directory()};
  std::map<Addr, std::uint32_t> model;  // non-UNMAPPED entries only
  std::map<BlockId, std::uint64_t> stamp;
  std::uint64_t now = 0;
  std::mt19937 gen(seed);
  auto rng = [&] { return std::uint32_t(gen()); };
  std::uint32_t next_cache_slot = 0;
  std::uint64_t reclaims = 0;

  const auto random_addr = [&] {
    const std::uint32_t s = rng() % slots;
    // Mostly level 0 around block borders, sometimes coarser levels.
    const std::uint32_t l = rng() % 4 == 0 ? rng() % h.level_count() : 0u;
    const glm::uvec3 nb = h.level(l).bricks;
    glm::uvec3 b;
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t near = (rng() % ((nb[i] + 15u) / 16u)) * 16u;  // a block start
      const std::uint32_t c = rng() % 2 ? near + rng() % 3 : near + 16u - 1u - rng() % 3;
      b[i] = std::min(c, nb[i] - 1u);
      if (rng() % 3 == 0) b[i] = rng() % nb[i];
    }
    return PageAddress{s, l, b};
  };
  const auto mapped_in = [&](const BlockId& blk) {
    for (const auto& [a, e] : model)
      if (block_of(addr_of(a)) == blk && k::resoct_page_is_mapped(e)) return true;
    return false;
  };
  const auto allocated = [&] {
    std::set<BlockId> out;
    for (const auto& [blk, t] : stamp) out.insert(blk);
    return out;
  };
  // The block the table must reclaim next: least recently written, no MAPPED entry.
  const auto expected_victim = [&]() -> std::optional<BlockId> {
    std::optional<BlockId> best;
    for (const auto& [blk, t] : stamp) {
      if (mapped_in(blk)) continue;
      if (!best || t < stamp.at(*best)) best = blk;
    }
    return best;
  };

  for (int op = 0; op < 3000; ++op) {
    const PageAddress a = random_addr();
    const BlockId blk = block_of(a);
    const bool block_allocated = stamp.count(blk) != 0;
    const std::uint32_t before = model.count(key_of(a)) ? model.at(key_of(a)) : 0u;
    std::uint32_t value = 0;
    bool via_allocate = false;
    const std::uint32_t r = rng() % 16;
    std::size_t mapped_total = 0;
    for (const auto& [x, e] : model) mapped_total += k::resoct_page_is_mapped(e) ? 1u : 0u;
    if (r < 4 && mapped_total + 1 < max_blocks) {
      value = k::resoct_page_encode_mapped(next_cache_slot++ % 1000u);
    } else if (r < 8) {
      value = k::RESOCT_PAGE_EMPTY_WORD;
    } else if (r < 10) {
      value = k::resoct_page_encode_homogeneous(rng() % 65536u);
    } else if (r < 13) {
      value = k::RESOCT_PAGE_UNMAPPED_WORD;
    } else if (r < 15) {
      via_allocate = true;
    } else {
      // clear_slot against the model.
      const std::uint32_t s = rng() % slots;
      std::vector<std::uint32_t> expect;
      for (auto it = model.begin(); it != model.end();) {
        if (std::get<0>(it->first) == s) {
          if (k::resoct_page_is_mapped(it->second))
            expect.push_back(k::resoct_page_cache_slot(it->second));
          it = model.erase(it);
        } else {
          ++it;
        }
      }
      for (auto it = stamp.begin(); it != stamp.end();)
        it = std::get<0>(it->first) == s ? stamp.erase(it) : std::next(it);
      std::vector<std::uint32_t> got = pt.clear_slot(s);
      std::sort(got.begin(), got.end());
      std::sort(expect.begin(), expect.end());
      ASSERT_EQ(got, expect) << "op " << op;
      dev.apply(pt.take_deltas());
      continue;
    }
    // Does this operation allocate, and if the pool is full, which block goes?
    const bool allocates =
        !block_allocated && (via_allocate || value != k::RESOCT_PAGE_UNMAPPED_WORD);
    std::optional<BlockId> victim;
    if (allocates && pt.allocated_blocks() == max_blocks) {
      victim = expected_victim();
      ASSERT_TRUE(victim.has_value());
    }
    if (via_allocate) {
      pt.allocate_block(pt.directory_index(a));
    } else if (value == k::RESOCT_PAGE_UNMAPPED_WORD) {
      pt.set_unmapped(a);
    } else if (k::resoct_page_is_mapped(value)) {
      pt.set_mapped(a, k::resoct_page_cache_slot(value));
    } else if (value == k::RESOCT_PAGE_EMPTY_WORD) {
      pt.set_empty(a);
    } else {
      pt.set_homogeneous(a, double(k::resoct_page_payload(value)), ValueRange{0, 65535});
    }
    // Apply to the model: the victim's entries are dropped (none of them is MAPPED).
    if (victim) {
      ++reclaims;
      for (auto it = model.begin(); it != model.end();) {
        if (block_of(addr_of(it->first)) == *victim) {
          ASSERT_FALSE(k::resoct_page_is_mapped(it->second));
          it = model.erase(it);
        } else {
          ++it;
        }
      }
      stamp.erase(*victim);
    }
    if (!via_allocate) {
      if (value == k::RESOCT_PAGE_UNMAPPED_WORD) {
        model.erase(key_of(a));
      } else {
        model[key_of(a)] = value;
      }
    }
    if (allocates || (value != before && !via_allocate && stamp.count(blk))) stamp[blk] = ++now;

    // Check everything against the model: host entries, the allocated set, the mirror.
    dev.apply(pt.take_deltas());
    ASSERT_EQ(pt.allocated_blocks(), stamp.size()) << "op " << op;
    for (const auto& [x, e] : model) {
      ASSERT_EQ(pt.entry(addr_of(x)), e) << "op " << op;
      ASSERT_EQ(dev.entry(pt, addr_of(x)), e) << "op " << op;
    }
    const std::set<BlockId> alloc = allocated();
    for (int probe = 0; probe < 20; ++probe) {
      const PageAddress b = random_addr();
      const std::uint32_t want = model.count(key_of(b)) ? model.at(key_of(b)) : 0u;
      ASSERT_EQ(pt.entry(b), want) << "op " << op;
      ASSERT_EQ(dev.entry(pt, b), want) << "op " << op;
      ASSERT_EQ(pt.translate(b.level, b.slot,
                             (glm::dvec3(b.brick) * 8.0 + 0.5) *
                                 glm::dvec3(1u << h.level(b.level).factor_log2.x,
                                            1u << h.level(b.level).factor_log2.y,
                                            1u << h.level(b.level).factor_log2.z) /
                                 glm::dvec3(h.volume().extent))
                    .entry,
                want);
      // Keys: a brick key exactly when the block is allocated, decoding back to the brick.
      const std::uint32_t key = pt.device_key(b);
      if (alloc.count(block_of(b))) {
        ASSERT_FALSE(k::resoct_request_key_is_block_miss(key));
        ASSERT_EQ(pt.decode_device_key(key), b);
      } else {
        ASSERT_TRUE(k::resoct_request_key_is_block_miss(key));
        ASSERT_EQ(pt.decode_block_miss(key), (BlockMiss{b.slot, b.level, pt.directory_index(b)}));
      }
    }
  }
  ASSERT_EQ(dev.dir, pt.directory());
  EXPECT_GT(reclaims, 10u);  // the pool was exhausted and reclaimed many times
}

}  // namespace

TEST(PageTableSparse, MatchesModelUnderRandomOpsWithPoolExhaustion) {
  run_model(11, 6);
  run_model(12, 9);
}

TEST(PageTableSparse, FullPoolOfMappedBlocksIsAnErrorNamingMaxBlocks) {
  const BrickHierarchy h = make({320, 168, 280}, glm::uvec3(8));
  PageTable pt(h, 1, 2);
  pt.set_mapped({0, 0, {0, 0, 0}}, 1);
  pt.set_mapped({0, 0, {16, 0, 0}}, 2);
  EXPECT_RESOCT_ERROR(pt.set_mapped({0, 0, {32, 0, 0}}, 3), ErrorCode::invalid_argument,
                      "max_blocks");
  // Once a block holds no MAPPED entry it can be reclaimed.
  pt.set_empty({0, 0, {0, 0, 0}});
  pt.set_mapped({0, 0, {32, 0, 0}}, 3);
  EXPECT_EQ(pt.entry({0, 0, {0, 0, 0}}), k::RESOCT_PAGE_UNMAPPED_WORD);  // dropped with its block
  EXPECT_EQ(pt.entry({0, 0, {32, 0, 0}}), k::resoct_page_encode_mapped(3));
  EXPECT_RESOCT_ERROR(pt.allocate_block(std::uint32_t(pt.directory().size())),
                      ErrorCode::out_of_range, "directory index");
}

TEST(PageTableSparse, HostileKeysDecodeToNothing) {
  const BrickHierarchy h = make({320, 168, 280}, glm::uvec3(8));
  PageTable pt(h, 2, 8);
  const PageAddress a{1, 0, {39, 20, 34}};  // the last brick: a partial block
  pt.set_empty(a);
  const std::uint32_t key = pt.device_key(a);
  ASSERT_EQ(pt.decode_device_key(key), a);
  const std::uint32_t block = k::resoct_request_key_pool_block(key);
  // The same block, an entry beyond the level's bricks (x = 40 does not exist).
  EXPECT_FALSE(pt.decode_device_key(k::resoct_request_key_brick(block, 8u | (4u << 4) | (2u << 8)))
                   .has_value());
  // Allocated-but-never-used blocks, block 0, and blocks past the pool.
  for (std::uint32_t b : {0u, block + 1u, pt.pool_block_count(), 0x7FFFFu}) {
    EXPECT_FALSE(pt.decode_device_key(k::resoct_request_key_brick(b, 0)).has_value()) << b;
  }
  // A freed block no longer decodes.
  pt.clear_slot(1);
  EXPECT_FALSE(pt.decode_device_key(key).has_value());
  EXPECT_FALSE(pt.decode_block_miss(k::resoct_request_key_block_miss(0x7FFFFFFEu)).has_value());
  // Random words: whatever decodes names a brick whose key is that word again.
  std::mt19937 gen(3);
  pt.set_mapped({0, 1, {3, 2, 1}}, 5);
  pt.set_homogeneous({1, 0, {17, 0, 33}}, 4.0, ValueRange{0, 255});
  std::uint32_t decoded = 0;
  for (int i = 0; i < 200000; ++i) {
    std::uint32_t w = std::uint32_t(gen());
    if (i % 2) w &= 0x0000FFFFu | (w & 0x80000000u);  // small block indices: more real blocks
    if (const auto b = pt.decode_device_key(w)) {
      EXPECT_EQ(pt.device_key(*b), w);
      ++decoded;
    }
    if (const auto m = pt.decode_block_miss(w)) {
      EXPECT_LT(m->directory_index, pt.directory().size());
      EXPECT_EQ(m->directory_index, k::resoct_request_key_directory(w));
    }
  }
  EXPECT_GT(decoded, 0u);
}

TEST(PageTableSparse, Volume65536CubedNeedsOnlyItsDirectoryAndUsedBlocks) {
  // 65536^3 voxels in 32^3 bricks: 2^33 bricks at level 0, 128^3 directory entries.
  const BrickHierarchy h = make({65536, 65536, 65536}, glm::uvec3(32));
  ASSERT_EQ(h.level(0).brick_count, std::uint64_t(1) << 33);
  PageTable pt(h, 4, 64);
  std::uint64_t expect_dir = 0;
  for (std::uint32_t l = 0; l < h.level_count(); ++l) {
    const glm::u64vec3 n =
        (glm::u64vec3(h.level(l).bricks) + std::uint64_t(15)) / std::uint64_t(16);
    expect_dir += n.x * n.y * n.z;
  }
  EXPECT_EQ(pt.directory().size(), expect_dir * 4u);
  EXPECT_EQ(pt.pool().size(), 4096u);  // only block 0 until something is written
  const PageAddress far{3, 0, {2047, 2047, 2047}}, near{3, 0, {0, 0, 0}};
  pt.set_mapped(far, 7);
  pt.set_empty(near);
  EXPECT_EQ(pt.allocated_blocks(), 2u);
  EXPECT_EQ(pt.pool().size(), 3u * 4096u);
  EXPECT_EQ(pt.decode_device_key(pt.device_key(far)), far);
  EXPECT_EQ(pt.translate(0, 3, glm::dvec3(1.0)).cache_slot(), 7u);
  EXPECT_EQ(pt.translate(0, 3, glm::dvec3(0.0)).entry, k::RESOCT_PAGE_EMPTY_WORD);
  EXPECT_EQ(pt.translate(0, 2, glm::dvec3(1.0)).entry, k::RESOCT_PAGE_UNMAPPED_WORD);
  const std::uint32_t miss = pt.device_key({0, 0, {1000, 5, 2047}});
  ASSERT_TRUE(k::resoct_request_key_is_block_miss(miss));
  EXPECT_EQ(pt.decode_block_miss(miss)->level, 0u);
}
