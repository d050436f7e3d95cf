// Page table: address translation against a brute-force integer definition for every voxel of
// awkward volumes at every level, the delta lists, homogeneous values, and limits. The sparse
// two-level layout (blocks, pool, reclaim, device keys) is tested in test_page_table_sparse.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "resoct/kernel/request_key.glsl.h"
#include "resoct/engine/page_table.hpp"
#include "support/expect_error.hpp"

using namespace resoct;
namespace k = resoct::kernel;

namespace {

BrickHierarchy make(glm::u64vec3 extent, glm::uvec3 brick, std::uint32_t halo) {
  VolumeDesc v;
  v.extent = extent;
  return BrickHierarchy(v, BrickLayout{brick, halo});
}

std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) {
  return (a + b - 1) / b;
}

// Independent model of the layout: per level extents and bricks, per table the first directory
// entry (tables in (slot, level) order, blocks of 16^3 bricks x fastest).
struct BruteLayout {
  std::vector<glm::u64vec3> extent;  // per level
  std::vector<glm::u64vec3> bricks;
  std::vector<glm::u64vec3> blocks;
  std::vector<std::uint64_t> offset;  // per table, into the directory
  std::vector<std::uint64_t> flat;    // per table, in a flat x-fastest numbering of all bricks
  BruteLayout(const BrickHierarchy& h, std::uint32_t slots) {
    std::uint64_t at = 0, flat_at = 0;
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      glm::u64vec3 e, b;
      for (int i = 0; i < 3; ++i) {
        const std::uint64_t f = std::uint64_t(1) << h.level(l).factor_log2[i];
        e[i] = ceil_div(h.volume().extent[i], f);
        b[i] = ceil_div(e[i], h.layout().brick_size[i]);
      }
      extent.push_back(e);
      bricks.push_back(b);
      blocks.push_back(glm::u64vec3(ceil_div(b.x, 16), ceil_div(b.y, 16), ceil_div(b.z, 16)));
    }
    for (std::uint32_t s = 0; s < slots; ++s) {
      for (std::uint32_t l = 0; l < h.level_count(); ++l) {
        offset.push_back(at);
        flat.push_back(flat_at);
        at += blocks[l].x * blocks[l].y * blocks[l].z;
        flat_at += bricks[l].x * bricks[l].y * bricks[l].z;
      }
    }
  }
  std::uint64_t flat_index(std::uint32_t table, std::uint32_t l, glm::u64vec3 br) const {
    return flat[table] + br.x + bricks[l].x * (br.y + bricks[l].y * br.z);
  }
  std::uint64_t directory_index(std::uint32_t table, std::uint32_t l, glm::u64vec3 br) const {
    const glm::u64vec3 b = br / std::uint64_t(16);
    return offset[table] + b.x + blocks[l].x * (b.y + blocks[l].y * b.z);
  }
};

void check_every_voxel(const BrickHierarchy& h, std::uint32_t slots) {
  const BruteLayout bl(h, slots);
  PageTable pt(h, slots, std::uint32_t(PageTable::block_count(h, slots)));
  // Give each brick a distinct MAPPED entry so that the looked-up word identifies the brick.
  for (std::uint32_t s = 0; s < slots; ++s)
    for (std::uint32_t l = 0; l < h.level_count(); ++l)
      for (std::uint32_t z = 0; z < bl.bricks[l].z; ++z)
        for (std::uint32_t y = 0; y < bl.bricks[l].y; ++y)
          for (std::uint32_t x = 0; x < bl.bricks[l].x; ++x) {
            const PageAddress a{s, l, {x, y, z}};
            const std::uint32_t t = s * h.level_count() + l;
            pt.set_mapped(a, std::uint32_t(bl.flat_index(t, l, {x, y, z})) * 7u + 1u);
            ASSERT_EQ(pt.directory_index(a), bl.directory_index(t, l, {x, y, z}));
          }
  const glm::u64vec3 e0 = h.volume().extent;
  const glm::uvec3 b = h.layout().brick_size;
  const std::uint32_t halo = h.layout().halo;
  std::uint64_t checked = 0;
  for (std::uint64_t z = 0; z < e0.z; ++z)
    for (std::uint64_t y = 0; y < e0.y; ++y)
      for (std::uint64_t x = 0; x < e0.x; ++x) {
        const glm::u64vec3 u(x, y, z);
        const glm::dvec3 p = (glm::dvec3(u) + 0.5) / glm::dvec3(e0);
        for (std::uint32_t l = 0; l < h.level_count(); ++l) {
          const std::uint32_t s = std::uint32_t((x + y + z + l) % slots);
          glm::u64vec3 v, br, off;
          for (int i = 0; i < 3; ++i) {
            v[i] = u[i] >> h.level(l).factor_log2[i];
            br[i] = v[i] / b[i];
            off[i] = v[i] % b[i] + halo;
          }
          const std::uint64_t idx = bl.flat_index(s * h.level_count() + l, l, br);
          const PageLookup r = pt.translate(l, s, p);
          ASSERT_EQ(glm::u64vec3(r.voxel), v) << "voxel " << x << "," << y << "," << z << " l" << l;
          ASSERT_EQ(glm::u64vec3(r.brick), br);
          ASSERT_EQ(glm::u64vec3(r.padded_offset), off);
          ASSERT_EQ(r.entry, k::resoct_page_encode_mapped(std::uint32_t(idx) * 7u + 1u));
          ASSERT_EQ(r.cache_slot(), std::uint32_t(idx) * 7u + 1u);
          ++checked;
        }
      }
  EXPECT_EQ(checked, e0.x * e0.y * e0.z * h.level_count());
}

}  // namespace

TEST(PageTable, TranslationMatchesBruteForceForEveryVoxel_40x33x17) {
  check_every_voxel(make({40, 33, 17}, glm::uvec3(8), 1), 2);
}

TEST(PageTable, TranslationMatchesBruteForceForEveryVoxel_795x3x1) {
  check_every_voxel(make({795, 3, 1}, glm::uvec3(8), 2), 3);
}

TEST(PageTable, TranslationMatchesBruteForceForEveryVoxel_AnisotropicBricks) {
  check_every_voxel(make({37, 50, 23}, glm::uvec3(4, 5, 6), 0), 1);
}

TEST(PageTable, TranslationClampsAndHandlesFacesAndBrickBorders) {
  const BrickHierarchy h = make({40, 33, 17}, glm::uvec3(8), 1);
  PageTable pt(h, 1, 4);
  // p = 1 lies on the far face and belongs to the last voxel (in the partial last brick).
  PageLookup r = pt.translate(0, 0, glm::dvec3(1.0));
  EXPECT_EQ(r.voxel, glm::uvec3(39, 32, 16));
  EXPECT_EQ(r.brick, glm::uvec3(4, 4, 2));
  EXPECT_EQ(r.padded_offset, glm::uvec3(8, 1, 1));
  EXPECT_FALSE(r.mapped());
  EXPECT_FALSE(r.cache_slot().has_value());
  r = pt.translate(0, 0, glm::dvec3(-0.5, 2.0, 0.0));
  EXPECT_EQ(r.voxel, glm::uvec3(0, 32, 0));
  r = pt.translate(1, 0, glm::dvec3(std::nan(""), 1.0, 0.5));
  EXPECT_EQ(r.voxel, glm::uvec3(0, 16, 8));  // level 1 is 20 x 17 x 17
  // Exactly on a brick border: voxel 8 starts brick 1.
  r = pt.translate(0, 0, glm::dvec3(8.0 / 40.0, 0.0, 0.0));
  EXPECT_EQ(r.voxel.x, 8u);
  EXPECT_EQ(r.brick.x, 1u);
  EXPECT_EQ(r.padded_offset.x, 1u);
  EXPECT_RESOCT_ERROR(pt.translate(h.level_count(), 0, glm::dvec3(0.5)), ErrorCode::out_of_range,
                      "level");
  EXPECT_RESOCT_ERROR(pt.translate(0, 1, glm::dvec3(0.5)), ErrorCode::out_of_range, "slot");
}

TEST(PageTable, DeltasAreDeduplicatedAndReproduceTheTable) {
  const BrickHierarchy h = make({40, 33, 17}, glm::uvec3(8), 1);
  PageTable pt(h, 2, std::uint32_t(PageTable::block_count(h, 2)));
  std::mt19937 gen(1234);
  auto rng = [&] { return std::uint32_t(gen()); };
  // What a backend holds: the whole pool and the directory.
  std::vector<std::uint32_t> pool(std::size_t(pt.pool_block_count()) * 4096u, 0u);
  std::vector<std::uint32_t> dir = pt.directory();
  for (int round = 0; round < 20; ++round) {
    const int ops = int(rng() % 300);
    for (int i = 0; i < ops; ++i) {
      const std::uint32_t s = rng() % 2, l = rng() % h.level_count();
      const glm::uvec3 nb = h.level(l).bricks;
      const PageAddress a{s, l, {rng() % nb.x, rng() % nb.y, rng() % nb.z}};
      switch (rng() % 4) {
        case 0: pt.set_mapped(a, rng() % 64); break;
        case 1: pt.set_empty(a); break;
        case 2: pt.set_unmapped(a); break;
        default: pt.set_homogeneous(a, double(rng() % 256), ValueRange{0, 255}); break;
      }
    }
    const PageTableDeltas d = pt.take_deltas();
    for (const auto* list : {&d.pool, &d.directory}) {
      for (std::size_t i = 1; i < list->size(); ++i) {
        EXPECT_LT((*list)[i - 1].index, (*list)[i].index);  // sorted and unique
      }
    }
    for (const PageDelta& x : d.pool) {
      EXPECT_EQ(x.value, pt.pool()[x.index]);
      pool[x.index] = x.value;
    }
    for (const PageDelta& x : d.directory) {
      EXPECT_EQ(x.value, pt.directory()[x.index]);
      dir[x.index] = x.value;
    }
    ASSERT_EQ(dir, pt.directory());
    ASSERT_TRUE(std::equal(pt.pool().begin(), pt.pool().end(), pool.begin()));
    // Every brick reads the same through the mirror as through the host.
    for (std::uint32_t s = 0; s < 2; ++s)
      for (std::uint32_t l = 0; l < h.level_count(); ++l) {
        const glm::uvec3 nb = h.level(l).bricks;
        for (std::uint32_t z = 0; z < nb.z; ++z)
          for (std::uint32_t y = 0; y < nb.y; ++y)
            for (std::uint32_t x = 0; x < nb.x; ++x) {
              const PageAddress a{s, l, {x, y, z}};
              const std::uint32_t b = dir[pt.directory_index(a)];
              ASSERT_EQ(pool[b * 4096u + k::resoct_page_in_block_index(a.brick)], pt.entry(a));
            }
      }
    EXPECT_EQ(pt.pending_delta_count(), 0u);
  }
  const PageTableDeltas none = pt.take_deltas();
  EXPECT_TRUE(none.pool.empty() && none.directory.empty());
}

TEST(PageTable, HomogeneousKeepsTheExactValueOnTheHost) {
  const BrickHierarchy h = make({40, 33, 17}, glm::uvec3(8), 1);
  PageTable pt(h, 1, 8);
  const PageAddress a{0, 0, {1, 2, 0}}, b{0, 1, {0, 0, 0}};
  pt.set_homogeneous(a, 1234.0, ValueRange{0, 65535});  // u16, default range: exact in unorm16
  EXPECT_EQ(pt.entry(a), k::resoct_page_encode_homogeneous(1234u));
  EXPECT_EQ(pt.homogeneous_value(a), 1234.0);
  const double f = 0.123456789012345;  // f32 data: the device sees the rounded unorm16
  pt.set_homogeneous(b, f, ValueRange{0, 1});
  EXPECT_EQ(k::resoct_page_payload(pt.entry(b)), std::uint32_t(std::lround(f * 65535.0)));
  EXPECT_EQ(pt.homogeneous_value(b), f);
  pt.set_homogeneous(b, 7.5, ValueRange{0, 1});  // outside the range: clamped on the device only
  EXPECT_EQ(k::resoct_page_payload(pt.entry(b)), 65535u);
  EXPECT_EQ(pt.homogeneous_value(b), 7.5);
  pt.set_mapped(b, 3);
  EXPECT_FALSE(pt.homogeneous_value(b).has_value());
  EXPECT_RESOCT_ERROR(pt.set_homogeneous(a, std::nan(""), ValueRange{}),
                      ErrorCode::invalid_argument, "value");
}

TEST(PageTable, ClearSlotReleasesOnlyThatSlotsMappedBricks) {
  const BrickHierarchy h = make({40, 33, 17}, glm::uvec3(8), 1);
  PageTable pt(h, 3, std::uint32_t(PageTable::block_count(h, 3)));
  std::vector<std::uint32_t> expect;
  std::mt19937 gen(5);
  auto rng = [&] { return std::uint32_t(gen()); };
  std::uint32_t next_slot = 0;
  for (std::uint32_t s = 0; s < 3; ++s)
    for (std::uint32_t l = 0; l < h.level_count(); ++l) {
      const glm::uvec3 nb = h.level(l).bricks;
      for (std::uint32_t i = 0; i < nb.x * nb.y * nb.z; i += 1 + rng() % 3) {
        const PageAddress a{s, l, {i % nb.x, (i / nb.x) % nb.y, i / (nb.x * nb.y)}};
        if (rng() % 2) {
          pt.set_mapped(a, next_slot);
          if (s == 1) expect.push_back(next_slot);
          ++next_slot;
        } else {
          pt.set_empty(a);
        }
      }
    }
  pt.take_deltas();
  std::vector<std::uint32_t> before;  // every entry of every slot, in address order
  const auto each = [&](auto&& fn) {
    for (std::uint32_t s = 0; s < 3; ++s)
      for (std::uint32_t l = 0; l < h.level_count(); ++l) {
        const glm::uvec3 nb = h.level(l).bricks;
        for (std::uint32_t i = 0; i < nb.x * nb.y * nb.z; ++i)
          fn(PageAddress{s, l, {i % nb.x, (i / nb.x) % nb.y, i / (nb.x * nb.y)}});
      }
  };
  each([&](const PageAddress& a) { before.push_back(pt.entry(a)); });
  const std::vector<std::uint32_t> dir_before = pt.directory();
  std::vector<std::uint32_t> got = pt.clear_slot(1);
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, expect);
  std::size_t i = 0;
  each([&](const PageAddress& a) {
    EXPECT_EQ(pt.entry(a), a.slot == 1 ? k::RESOCT_PAGE_UNMAPPED_WORD : before[i]);
    ++i;
  });
  // Slot 1's blocks are freed (directory 0), the others keep theirs.
  const std::uint32_t lo = pt.directory_offsets()[pt.table_id(1, 0)];
  const std::uint32_t hi = pt.directory_offsets()[pt.table_id(2, 0)];
  for (std::uint32_t d = 0; d < pt.directory().size(); ++d) {
    EXPECT_EQ(pt.directory()[d], d >= lo && d < hi ? 0u : dir_before[d]);
  }
  const PageTableDeltas d = pt.take_deltas();
  for (const PageDelta& x : d.directory) {
    EXPECT_TRUE(x.index >= lo && x.index < hi);
    EXPECT_EQ(x.value, 0u);
  }
  for (const PageDelta& x : d.pool) EXPECT_EQ(x.value, k::RESOCT_PAGE_UNMAPPED_WORD);
}

TEST(PageTable, DeviceKeysRoundTripAndForeignKeysAreRejected) {
  const BrickHierarchy h = make({795, 3, 1}, glm::uvec3(8), 1);
  PageTable pt(h, 2, std::uint32_t(PageTable::block_count(h, 2)));
  std::map<std::uint32_t, bool> seen;
  for (int pass = 0; pass < 2; ++pass) {
    for (std::uint32_t s = 0; s < 2; ++s)
      for (std::uint32_t l = 0; l < h.level_count(); ++l)
        for (std::uint32_t x = 0; x < h.level(l).bricks.x; ++x) {
          const PageAddress a{s, l, {x, 0, 0}};
          const std::uint32_t key = pt.device_key(a);
          if (pass == 0) {
            // Unallocated: the block-miss key of the brick's block.
            ASSERT_TRUE(k::resoct_request_key_is_block_miss(key));
            EXPECT_FALSE(pt.decode_device_key(key).has_value());
            EXPECT_EQ(pt.decode_block_miss(key), (BlockMiss{s, l, pt.directory_index(a)}));
          } else {
            ASSERT_FALSE(k::resoct_request_key_is_block_miss(key));
            EXPECT_FALSE(seen[key]);
            seen[key] = true;
            EXPECT_EQ(pt.decode_device_key(key), a);
            EXPECT_FALSE(pt.decode_block_miss(key).has_value());
          }
        }
    for (std::uint32_t d = 0; d < pt.directory().size(); ++d) pt.allocate_block(d);
  }
  EXPECT_FALSE(pt.decode_device_key(k::RESOCT_REQUEST_KEY_NONE).has_value());
  EXPECT_FALSE(pt.decode_block_miss(k::RESOCT_REQUEST_KEY_NONE).has_value());
  EXPECT_FALSE(pt.decode_device_key(k::resoct_request_key_brick(0, 0)).has_value());
  EXPECT_FALSE(
      pt.decode_device_key(k::resoct_request_key_brick(pt.pool_block_count(), 0)).has_value());
  EXPECT_FALSE(
      pt.decode_block_miss(k::resoct_request_key_block_miss(std::uint32_t(pt.directory().size())))
          .has_value());
  EXPECT_RESOCT_ERROR(pt.device_key(PageAddress{0, 0, {100, 0, 0}}), ErrorCode::out_of_range,
                      "outside level");
}

TEST(PageTable, RejectsParametersThatDoNotFitDeviceKeys) {
  const BrickHierarchy h = make({40, 33, 17}, glm::uvec3(8), 1);
  EXPECT_RESOCT_ERROR(PageTable(h, 0, 4), ErrorCode::invalid_argument, "slots");
  EXPECT_RESOCT_ERROR(PageTable(h, 1, 0), ErrorCode::invalid_argument, "max_blocks");
  EXPECT_NO_THROW(PageTable(h, 1, k::RESOCT_REQUEST_MAX_POOL_BLOCKS - 1u));
  EXPECT_RESOCT_ERROR(PageTable(h, 1, k::RESOCT_REQUEST_MAX_POOL_BLOCKS),
                      ErrorCode::invalid_argument, "max_blocks");
  // The old limit of 128 (slot, level) tables is gone: 32 slots x 7 levels.
  EXPECT_NO_THROW(PageTable(make({600, 600, 600}, glm::uvec3(8), 1), 32, 16));
  // 65536^3 voxels in 4^3 bricks: 1024^3 blocks at level 0 per slot; two slots need more than
  // 2^31 - 1 directory entries (checked before anything is allocated).
  const BrickHierarchy big = make({65536, 65536, 65536}, glm::uvec3(4), 0);
  EXPECT_GT(PageTable::block_count(big, 2), std::uint64_t(k::RESOCT_REQUEST_MAX_DIRECTORY));
  EXPECT_RESOCT_ERROR(PageTable(big, 2, 16), ErrorCode::invalid_argument, "slots");
}
