// resoct single-source kernel: the 32-bit device request key for a missing brick.
//
// Keys name page-table storage of the sparse two-level page table (kernel/page_entry.glsl.h):
//   bit 31 = 0  brick key: bits 12-30 pool block index (1 .. 2^19 - 1), bits 0-11 the brick's
//               entry in that block (resoct_page_in_block_index). Only possible when the
//               brick's block is allocated.
//   bit 31 = 1  block-miss key: bits 0-30 the global directory index of an unallocated block,
//               reported where a brick of that block would have been requested. The host then
//               allocates the block (all UNMAPPED); the next frame requests the bricks in it.
// Limits: fewer than 2^19 pool blocks and fewer than 2^31 directory entries in total (so the
// all-ones word, reserved as "no key" RESOCT_REQUEST_KEY_NONE, is never a real key). The host
// validates them (PageTable) and decodes keys before it changes the table in the same frame, so
// the pool blocks a key names still belong to the same blocks; keys are not trusted (a key naming
// a free block or an out-of-range directory index decodes to nothing).
//
// Node (metadata) requests do not use this layout: they are octree node indices kept in a
// separate request set, so brick and node keys never collide.
#ifndef RESOCT_KERNEL_REQUEST_KEY_GLSL_H
#define RESOCT_KERNEL_REQUEST_KEY_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_CONST(uint, RESOCT_REQUEST_BLOCK_MISS_BIT, 0x80000000u);
RESOCT_CONST(uint, RESOCT_REQUEST_IN_BLOCK_BITS, 12u);
RESOCT_CONST(uint, RESOCT_REQUEST_IN_BLOCK_MASK, 0x00000FFFu);
RESOCT_CONST(uint, RESOCT_REQUEST_POOL_BLOCK_MASK, 0x0007FFFFu);
// Pool blocks (including the permanent block 0) must stay at or below this count.
RESOCT_CONST(uint, RESOCT_REQUEST_MAX_POOL_BLOCKS, 0x00080000u);
// Directory entries in total must stay below this (the all-ones key is reserved).
RESOCT_CONST(uint, RESOCT_REQUEST_MAX_DIRECTORY, 0x7FFFFFFFu);
RESOCT_CONST(uint, RESOCT_REQUEST_KEY_NONE, 0xFFFFFFFFu);

RESOCT_FN uint resoct_request_key_brick(uint pool_block, uint in_block) {
  return ((pool_block & RESOCT_REQUEST_POOL_BLOCK_MASK) << RESOCT_REQUEST_IN_BLOCK_BITS) |
         (in_block & RESOCT_REQUEST_IN_BLOCK_MASK);
}

RESOCT_FN uint resoct_request_key_block_miss(uint directory_index) {
  return RESOCT_REQUEST_BLOCK_MISS_BIT | directory_index;
}

RESOCT_FN bool resoct_request_key_is_block_miss(uint key) {
  return (key & RESOCT_REQUEST_BLOCK_MISS_BIT) != 0u;
}

RESOCT_FN uint resoct_request_key_pool_block(uint key) {
  return (key >> RESOCT_REQUEST_IN_BLOCK_BITS) & RESOCT_REQUEST_POOL_BLOCK_MASK;
}

RESOCT_FN uint resoct_request_key_in_block(uint key) {
  return key & RESOCT_REQUEST_IN_BLOCK_MASK;
}

RESOCT_FN uint resoct_request_key_directory(uint key) {
  return key & ~RESOCT_REQUEST_BLOCK_MISS_BIT;
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
