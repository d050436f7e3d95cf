// resoct single-source kernel: the page-table entry word (one uint per brick, per slot and level).
//
// Layout of an entry (std430-safe: a plain uint in a storage buffer):
//   bits 30-31  state: UNMAPPED (0), MAPPED (1), EMPTY (2), HOMOGENEOUS (3)
//   bits  0-29  payload:
//               MAPPED       bits 0-25 cache slot index, 0 .. RESOCT_PAGE_MAX_CACHE_SLOT;
//                            bits 26-29 the brick's error code (below)
//               EMPTY        0: the brick is constant zero (transparent unless the transfer
//                            function shows 0, ResoctSlotInfo.zero_visible); 1: the brick
//                            holds no finite value (transparent for every transfer function)
//               HOMOGENEOUS  bits 0-15 the constant value as unorm16 of the channel's
//                            value range, bits 16-25 zero, bits 26-29 the error code
//               UNMAPPED     0
// Error code k (error-bounded level of detail, docs/rendering.md "Error-bounded LOD"): the
// brick's measured down-sampling error is at most 2^-k of the channel's value range (the largest
// difference between the level's trilinear reconstruction and the level-0 voxels it summarizes,
// at their centres). k = 0 says nothing (error up to the whole range: unknown, or level 0 where
// it is never read); 15 is also what an error of 0 gets.
// UNMAPPED is the all-zero word so that a zero-filled buffer is a valid, empty page table.
//
// Precision of HOMOGENEOUS: the device sees the value quantised to 1/65535 of the channel's value
// range, which is exact for u8 and for u16 with the default range. The host page table keeps the
// exact value (u16 or f32) beside the entry, so nothing is lost for host-side consumers.
#ifndef RESOCT_KERNEL_PAGE_ENTRY_GLSL_H
#define RESOCT_KERNEL_PAGE_ENTRY_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_CONST(uint, RESOCT_PAGE_STATE_SHIFT, 30u);
RESOCT_CONST(uint, RESOCT_PAGE_PAYLOAD_MASK, 0x3FFFFFFFu);
RESOCT_CONST(uint, RESOCT_PAGE_STATE_UNMAPPED, 0u);
RESOCT_CONST(uint, RESOCT_PAGE_STATE_MAPPED, 1u);
RESOCT_CONST(uint, RESOCT_PAGE_STATE_EMPTY, 2u);
RESOCT_CONST(uint, RESOCT_PAGE_STATE_HOMOGENEOUS, 3u);
// Largest cache slot index a MAPPED entry can hold (2^26 - 1, ~64 M bricks).
RESOCT_CONST(uint, RESOCT_PAGE_MAX_CACHE_SLOT, 0x03FFFFFFu);
// The error code's place in MAPPED and HOMOGENEOUS entries, and its largest value.
RESOCT_CONST(uint, RESOCT_PAGE_ERROR_SHIFT, 26u);
RESOCT_CONST(uint, RESOCT_PAGE_ERROR_MAX, 15u);
RESOCT_CONST(uint, RESOCT_PAGE_HOMOGENEOUS_MASK, 0xFFFFu);
RESOCT_CONST(uint, RESOCT_PAGE_UNMAPPED_WORD, 0u);
RESOCT_CONST(uint, RESOCT_PAGE_EMPTY_WORD, 0x80000000u);
RESOCT_CONST(uint, RESOCT_PAGE_EMPTY_NAN_WORD, 0x80000001u);

RESOCT_FN uint resoct_page_state(uint entry) {
  return entry >> RESOCT_PAGE_STATE_SHIFT;
}

RESOCT_FN uint resoct_page_payload(uint entry) {
  return entry & RESOCT_PAGE_PAYLOAD_MASK;
}

RESOCT_FN uint resoct_page_encode_mapped(uint cache_slot) {
  return (RESOCT_PAGE_STATE_MAPPED << RESOCT_PAGE_STATE_SHIFT) |
         (cache_slot & RESOCT_PAGE_MAX_CACHE_SLOT);
}

RESOCT_FN uint resoct_page_encode_homogeneous(uint unorm16) {
  return (RESOCT_PAGE_STATE_HOMOGENEOUS << RESOCT_PAGE_STATE_SHIFT) |
         (unorm16 & RESOCT_PAGE_HOMOGENEOUS_MASK);
}

// A MAPPED or HOMOGENEOUS entry with error code `code` (0 .. RESOCT_PAGE_ERROR_MAX).
RESOCT_FN uint resoct_page_with_error(uint entry, uint code) {
  return entry | (min(code, RESOCT_PAGE_ERROR_MAX) << RESOCT_PAGE_ERROR_SHIFT);
}

// The error code of a MAPPED or HOMOGENEOUS entry (0 for the other states).
RESOCT_FN uint resoct_page_error_code(uint entry) {
  uint state = entry >> RESOCT_PAGE_STATE_SHIFT;
  return state == RESOCT_PAGE_STATE_MAPPED || state == RESOCT_PAGE_STATE_HOMOGENEOUS
             ? (entry >> RESOCT_PAGE_ERROR_SHIFT) & RESOCT_PAGE_ERROR_MAX
             : 0u;
}

RESOCT_FN bool resoct_page_is_mapped(uint entry) {
  return resoct_page_state(entry) == RESOCT_PAGE_STATE_MAPPED;
}

// Cache slot of a MAPPED entry (meaningless for other states).
RESOCT_FN uint resoct_page_cache_slot(uint entry) {
  return entry & RESOCT_PAGE_MAX_CACHE_SLOT;
}

// Normalised [0, 1] value of a HOMOGENEOUS entry; EMPTY reads as 0.
RESOCT_FN float resoct_page_homogeneous_value(uint entry) {
  return float(entry & RESOCT_PAGE_HOMOGENEOUS_MASK) / 65535.0f;
}

// True when the entry needs no brick access: EMPTY or HOMOGENEOUS.
RESOCT_FN bool resoct_page_is_constant(uint entry) {
  return resoct_page_state(entry) >= RESOCT_PAGE_STATE_EMPTY;
}

// Index of a brick within one (slot, level) table: x fastest, as BrickHierarchy::linear_index.
RESOCT_FN uint resoct_page_local_index(uvec3 brick, uvec3 bricks) {
  return brick.x + bricks.x * (brick.y + bricks.y * brick.z);
}

// The sparse two-level layout: each (slot, level) table is cut into blocks of 16^3 bricks; a
// per-table directory (x fastest over the table's block grid) holds one pool block index per
// block, and pool block b holds the 4096 entries of its block at words [b * 4096, b * 4096 +
// 4096), x fastest. Pool block 0 is permanently all UNMAPPED, so a directory word of 0 means
// "not allocated" and the lookup needs no branch.
RESOCT_CONST(uint, RESOCT_PAGE_BLOCK_LOG2, 4u);  // bricks per block axis: 16
RESOCT_CONST(uint, RESOCT_PAGE_BLOCK_MASK, 15u);
RESOCT_CONST(uint, RESOCT_PAGE_BLOCK_ENTRIES_LOG2, 12u);
RESOCT_CONST(uint, RESOCT_PAGE_BLOCK_ENTRIES, 4096u);

// Blocks per axis of a table with `bricks` bricks per axis.
RESOCT_FN uvec3 resoct_page_blocks(uvec3 bricks) {
  return (bricks + uvec3(RESOCT_PAGE_BLOCK_MASK)) >> uvec3(RESOCT_PAGE_BLOCK_LOG2);
}

// Index of a brick's block within its table's directory (x fastest).
RESOCT_FN uint resoct_page_block_index(uvec3 brick, uvec3 bricks) {
  uvec3 n = resoct_page_blocks(bricks);
  uvec3 b = brick >> uvec3(RESOCT_PAGE_BLOCK_LOG2);
  return b.x + n.x * (b.y + n.y * b.z);
}

// Index of a brick's entry within its pool block (x fastest).
RESOCT_FN uint resoct_page_in_block_index(uvec3 brick) {
  uvec3 i = brick & uvec3(RESOCT_PAGE_BLOCK_MASK);
  return i.x | (i.y << RESOCT_PAGE_BLOCK_LOG2) | (i.z << (2u * RESOCT_PAGE_BLOCK_LOG2));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_PAGE_ENTRY_GLSL_H
