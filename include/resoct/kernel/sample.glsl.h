// resoct kernel: page-table translation and trilinear brick sampling from an exact level-0
// position (integer cell + fraction in [0, 1)).
//
// Level l voxel i covers level-0 voxels [i << f, (i + 1) << f) per axis (f = factor_log2), so
// the continuous level-l position of level-0 position x is x / 2^f, computed without rounding
// the large part: (cell >> f) + ((cell & (2^f − 1)) + frac) / 2^f. The padded-brick coordinate
// subtracts the brick's first core voxel (integers) and adds the halo; voxel centres sit at
// j + 0.5, matching resoct_sample_cache. With a halo of at least one voxel, trilinear filtering
// never needs a neighbour brick.
//
// Accessors the including file must define BEFORE including (see traverse.glsl.h):
//   uint  resoct_read_page(uint index), uint resoct_read_directory(uint index),
//   uint  resoct_read_directory_offset(uint table),
//   float resoct_sample_cache(uint cache_slot, vec3 pos), void resoct_mark_used(uint cache_slot)
#ifndef RESOCT_KERNEL_SAMPLE_GLSL_H
#define RESOCT_KERNEL_SAMPLE_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_FN uvec3 resoct_level_factor(RESOCT_IN(ResoctLevelInfo) L) {
  return uvec3(L.factor_log2_x, L.factor_log2_y, L.factor_log2_z);
}

/// Brick of level L containing the level-0 cell (cell inside the volume).
RESOCT_FN uvec3 resoct_brick_at(RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size, ivec3 cell) {
  uvec3 v = uvec3(cell) >> resoct_level_factor(L);
  v = min(v, uvec3(L.extent_x - 1u, L.extent_y - 1u, L.extent_z - 1u));
  return min(v / brick_size, uvec3(L.bricks_x - 1u, L.bricks_y - 1u, L.bricks_z - 1u));
}

/// Global directory index of the block holding a brick of (slot, level).
RESOCT_FN uint resoct_page_directory_index(uint slot, uint level, uint level_count,
                                           RESOCT_IN(ResoctLevelInfo) L, uvec3 brick) {
  return resoct_read_directory_offset(resoct_request_table_id(slot, level, level_count)) +
         resoct_page_block_index(brick, uvec3(L.bricks_x, L.bricks_y, L.bricks_z));
}

/// The page entry of a brick of (slot, level): directory, then pool (block 0 reads UNMAPPED).
RESOCT_FN uint resoct_page_entry_of(uint slot, uint level, uint level_count,
                                    RESOCT_IN(ResoctLevelInfo) L, uvec3 brick) {
  uint block =
      resoct_read_directory(resoct_page_directory_index(slot, level, level_count, L, brick));
  return resoct_read_page((block << RESOCT_PAGE_BLOCK_ENTRIES_LOG2) |
                          resoct_page_in_block_index(brick));
}

/// Device request key of a brick of (slot, level): the brick key when its block is allocated,
/// else the block-miss key of the block (kernel/request_key.glsl.h).
RESOCT_FN uint resoct_brick_request_key(uint slot, uint level, uint level_count,
                                        RESOCT_IN(ResoctLevelInfo) L, uvec3 brick) {
  uint d = resoct_page_directory_index(slot, level, level_count, L, brick);
  uint block = resoct_read_directory(d);
  return block == 0u ? resoct_request_key_block_miss(d)
                     : resoct_request_key_brick(block, resoct_page_in_block_index(brick));
}

/// Continuous padded-brick coordinate of a level-0 position in a brick of level L.
RESOCT_FN vec3 resoct_padded_position(RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size, uint halo,
                                      uvec3 brick, ivec3 cell, vec3 frac) {
  uvec3 fl = resoct_level_factor(L);
  uvec3 c = uvec3(cell);
  uvec3 low_mask = (uvec3(1u) << fl) - uvec3(1u);
  vec3 inv_scale =
      vec3(1.0f / float(1u << fl.x), 1.0f / float(1u << fl.y), 1.0f / float(1u << fl.z));
  ivec3 whole = ivec3(c >> fl) - ivec3(brick * brick_size);
  return vec3(whole) + (vec3(c & low_mask) + frac) * inv_scale + vec3(float(halo));
}

/// Raw voxel value of a MAPPED entry at a level-0 position (trilinear through the halo); marks
/// the cache slot used.
RESOCT_FN float resoct_sample_mapped(uint entry, RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size,
                                     uint halo, uvec3 brick, ivec3 cell, vec3 frac) {
  uint cache_slot = resoct_page_cache_slot(entry);
  resoct_mark_used(cache_slot);
  return resoct_sample_cache(cache_slot,
                             resoct_padded_position(L, brick_size, halo, brick, cell, frac));
}

/// Level-0 lower corner and size (voxels) of a brick of level L, for skipping.
RESOCT_FN ivec3 resoct_brick_lo0(RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size, uvec3 brick) {
  return ivec3((brick * brick_size) << resoct_level_factor(L));
}
RESOCT_FN vec3 resoct_brick_size0(RESOCT_IN(ResoctLevelInfo) L, uvec3 brick_size) {
  return vec3(brick_size << resoct_level_factor(L));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_SAMPLE_GLSL_H
