// resoct single-source kernel: the 32-bit device request key for a missing brick.
//
// Layout:
//   bits 25-31  table id = slot * level_count + level, the index of the (slot, level) page table
//   bits  0-24  local brick index within that table (resoct_page_local_index)
// Limits: at most 128 page tables (visible slots x levels, e.g. 8 x 16 or 4 x 32) and at most
// 2^25 - 1 = 33,554,431 bricks per level (e.g. 10240^3 voxels at 32^3 bricks). The all-ones word
// is reserved as "no key" (RESOCT_REQUEST_KEY_NONE); the local index 2^25 - 1 is never valid so
// that no real key can equal it. The host validates a hierarchy against these limits (PageTable)
// and maps keys back to 64-bit BrickKeys through the channel map and the epoch they were recorded
// under.
//
// Node (metadata) requests do not use this layout: they are octree node indices kept in a
// separate request set, so brick and node keys never collide.
#ifndef RESOCT_KERNEL_REQUEST_KEY_GLSL_H
#define RESOCT_KERNEL_REQUEST_KEY_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_CONST(uint, RESOCT_REQUEST_BRICK_BITS, 25u);
RESOCT_CONST(uint, RESOCT_REQUEST_TABLE_BITS, 7u);
RESOCT_CONST(uint, RESOCT_REQUEST_BRICK_MASK, 0x01FFFFFFu);
RESOCT_CONST(uint, RESOCT_REQUEST_MAX_TABLES, 128u);
// Bricks per table must stay below this (the all-ones local index is reserved).
RESOCT_CONST(uint, RESOCT_REQUEST_MAX_BRICKS_PER_TABLE, 0x01FFFFFFu);
RESOCT_CONST(uint, RESOCT_REQUEST_KEY_NONE, 0xFFFFFFFFu);

RESOCT_FN uint resoct_request_key_encode(uint table_id, uint local_index) {
  return (table_id << RESOCT_REQUEST_BRICK_BITS) | (local_index & RESOCT_REQUEST_BRICK_MASK);
}

RESOCT_FN uint resoct_request_key_table(uint key) {
  return key >> RESOCT_REQUEST_BRICK_BITS;
}

RESOCT_FN uint resoct_request_key_local(uint key) {
  return key & RESOCT_REQUEST_BRICK_MASK;
}

RESOCT_FN uint resoct_request_table_id(uint slot, uint level, uint level_count) {
  return slot * level_count + level;
}

// Slot-wide hash for the open-addressing request set (a multiplicative Fibonacci hash): both the
// host set and a GPU set built the same way probe the same sequence.
RESOCT_FN uint resoct_request_key_hash(uint key, uint log2_capacity) {
  uint h = key * 0x9E3779B1u;
  h ^= h >> 16u;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13u;
  return log2_capacity == 0u ? 0u : (h >> (32u - log2_capacity));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_REQUEST_KEY_GLSL_H
