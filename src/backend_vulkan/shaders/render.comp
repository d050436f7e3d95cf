#version 450
// resoct Vulkan backend: one invocation renders one pixel with the single-source traversal
// kernel (resoct/kernel/traverse.glsl.h). The accessors below read storage buffers.
//
// The brick cache is a storage buffer of uint words holding voxels of the configured type, not an
// image: filtering is done here exactly like the CPU backend (same clamp, same 2x2x2 cell, same
// lerp order, `precise` so no FMA contraction), which keeps colours identical to the CPU oracle
// and avoids the unorm rounding and reduced filter precision of hardware samplers.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

layout(local_size_x_id = 10, local_size_y_id = 11, local_size_z = 1) in;

// 0 = u8, 1 = u16, 2 = f32 (resoct::VoxelType).
layout(constant_id = 0) const uint VOXEL_TYPE = 0u;
layout(constant_id = 1) const int PADDED_X = 34;
layout(constant_id = 2) const int PADDED_Y = 34;
layout(constant_id = 3) const int PADDED_Z = 34;
// Cache buffers in use (1..8); 1 removes the per-sample buffer choice.
layout(constant_id = 4) const uint CACHE_CHUNKS = 1u;

#include "resoct/kernel/frame.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

layout(push_constant) uniform Push {
  uint brick_capacity;  // power of two
  uint brick_log2_capacity;
  uint brick_max_probes;
  uint node_capacity;
  uint node_log2_capacity;
  uint node_max_probes;
  uint slots_per_chunk;  // cache slots per cache buffer
}
pc;

layout(std430, binding = 0) readonly buffer FrameBuf {
  ResoctFrame frame;
  ResoctFxFrame fx_frame;  // effect constants, right after the frame (std430: scalars only)
};
layout(std430, binding = 1) readonly buffer Slots {
  ResoctSlotInfo slots[];
};
layout(std430, binding = 2) readonly buffer Levels {
  ResoctLevelInfo levels[];
};
layout(std430, binding = 3) readonly buffer Depths {
  ResoctDepthInfo depths[];
};
layout(std430, binding = 4) readonly buffer Nodes {
  uint nodes[];
};
// The sparse page table (kernel/page_entry.glsl.h): pool blocks of 4096 entries, the directory
// of pool block indices (binding 21) and the first directory entry of each (slot, level) table.
layout(std430, binding = 5) readonly buffer Pages {
  uint pages[];
};
layout(std430, binding = 6) readonly buffer DirectoryOffsets {
  uint directory_offsets[];
};
layout(std430, binding = 21) readonly buffer Directory {
  uint directory[];
};
layout(std430, binding = 7) readonly buffer TfLuts {
  vec4 tf_entries[];
};
// The cache is split into up to 8 buffers of whole bricks (chunk c holds slots
// [c * slots_per_chunk, (c + 1) * slots_per_chunk)), because one storage buffer may not exceed
// maxStorageBufferRange (128 MiB on some devices). Chunk 0 is binding 8, chunks 1-7 bindings 14-20.
// Pre-integration tables (kernel/preintegration.glsl.h), 2048 entries per slot; one dummy entry
// when the frame does not use them.
layout(std430, binding = 22) readonly buffer PreintTables {
  vec4 preint_entries[];
};
// Opacity-corrected, premultiplied LUTs of the frame's step levels (kernel/step_lut.glsl.h).
layout(std430, binding = 23) readonly buffer StepLuts {
  vec4 step_lut_entries[];
};
// Per octree node: the frame's visible-subtree bits (render/visible_subtrees.hpp), all zero when
// the tables have none.
layout(std430, binding = 24) readonly buffer VisibleSubtrees {
  uint visible_subtree_words[];
};
layout(std430, binding = 8) readonly buffer Cache0 {
  uint cache0[];
};
layout(std430, binding = 14) readonly buffer Cache1 {
  uint cache1[];
};
layout(std430, binding = 15) readonly buffer Cache2 {
  uint cache2[];
};
layout(std430, binding = 16) readonly buffer Cache3 {
  uint cache3[];
};
layout(std430, binding = 17) readonly buffer Cache4 {
  uint cache4[];
};
layout(std430, binding = 18) readonly buffer Cache5 {
  uint cache5[];
};
layout(std430, binding = 19) readonly buffer Cache6 {
  uint cache6[];
};
layout(std430, binding = 20) readonly buffer Cache7 {
  uint cache7[];
};
// Request sets: keys in [0, capacity), hit counts in [capacity, 2 * capacity).
layout(std430, binding = 9) buffer BrickRequests {
  uint brick_req[];
};
layout(std430, binding = 10) buffer NodeRequests {
  uint node_req[];
};
layout(std430, binding = 11) buffer Used {
  uint used_bits[];
};
layout(std430, binding = 12) writeonly buffer Out {
  vec4 pixels[];
};
// 64-bit counters as (low, high) uint pairs, counter k at words 2k and 2k + 1 (STAT_* below).
layout(std430, binding = 13) buffer Stats {
  uint stats[];
};

const uint STAT_SAMPLES = 0u;
const uint STAT_NODES = 1u;
const uint STAT_ACCESSES = 2u;
const uint STAT_ITERATIONS = 3u;
const uint STAT_CAPS = 4u;
const uint STAT_REQUESTS = 5u;
const uint STAT_BRICK_DROPPED = 6u;
const uint STAT_NODE_DROPPED = 7u;
const uint STAT_SKIPPED = 8u;  // box units * 2^20, rounded per ray
const uint STAT_MARCHED = 9u;
const uint STAT_GRADIENTS = 10u;
const uint STAT_SHADOW_RAYS = 11u;
const uint STAT_COUNT = 12u;
const float DISTANCE_SCALE = 1048576.0;

// Requests this invocation could not insert (private per invocation, reduced with the rest).
uint g_brick_dropped = 0u;
uint g_node_dropped = 0u;

// Statistics are summed per workgroup in shared memory and added to the buffer with one atomic
// per counter and workgroup (instead of one per invocation, which serializes on the same words).
// Partial sums are exact 64-bit (lo, hi) pairs.
const uint WORKGROUP = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
shared uvec2 partial[STAT_COUNT][WORKGROUP];

uvec2 add64(uvec2 a, uvec2 b) {
  uint carry;
  uint lo = uaddCarry(a.x, b.x, carry);
  return uvec2(lo, a.y + b.y + carry);
}

// Exact 64-bit sums without 64-bit atomics: a carry out of the low word bumps the high word.
void stat_add64(uint counter, uvec2 v) {
  uint i = 2u * counter;
  uint hi = v.y;
  if (v.x != 0u) {
    uint old = atomicAdd(stats[i], v.x);
    if (old + v.x < old) hi += 1u;
  }
  if (hi != 0u) atomicAdd(stats[i + 1u], hi);
}

uint resoct_read_node(uint index) {
  return nodes[index];
}
uint resoct_read_page(uint index) {
  return pages[index];
}
uint resoct_read_directory(uint index) {
  return directory[index];
}
uint resoct_read_directory_offset(uint table) {
  return directory_offsets[table];
}
ResoctSlotInfo resoct_read_slot(uint i) {
  return slots[i];
}
ResoctLevelInfo resoct_read_level(uint l) {
  return levels[l];
}
ResoctDepthInfo resoct_read_depth(uint d) {
  return depths[d];
}
vec4 resoct_read_tf(uint slot, uint index) {
  return tf_entries[slot * 1024u + index];
}
vec4 resoct_read_preint(uint slot, uint index) {
  return preint_entries[slot * 2048u + index];
}
vec4 resoct_read_step_lut(uint index) {
  return step_lut_entries[index];
}
uint resoct_read_visible_subtrees(uint node) {
  return visible_subtree_words[node];
}
ResoctFxFrame resoct_read_fx_frame() {
  return fx_frame;
}
float resoct_read_level_size_log2(uint level) {
  return levels[level].size_log2;
}

// Voxel j (counted from the start of its chunk) of cache buffer `buf`, decoded per voxel type.
#define RESOCT_VOXEL(buf, j)                                                  \
  (VOXEL_TYPE == 0u   ? float((buf[(j) >> 2u] >> (((j)&3u) * 8u)) & 0xFFu)    \
   : VOXEL_TYPE == 1u ? float((buf[(j) >> 1u] >> (((j)&1u) * 16u)) & 0xFFFFu) \
                      : uintBitsToFloat(buf[(j)]))
// The 2x2x2 cell from one buffer: the chunk is chosen once per sample, not per voxel.
#define RESOCT_LOAD_CELL(buf)            \
  v000 = RESOCT_VOXEL(buf, i);           \
  v100 = RESOCT_VOXEL(buf, i + dx);      \
  v010 = RESOCT_VOXEL(buf, i + dy);      \
  v110 = RESOCT_VOXEL(buf, i + dy + dx); \
  v001 = RESOCT_VOXEL(buf, i + dz);      \
  v101 = RESOCT_VOXEL(buf, i + dz + dx); \
  v011 = RESOCT_VOXEL(buf, i + dz + dy); \
  v111 = RESOCT_VOXEL(buf, i + dz + dy + dx)

// As the CPU backend: clamp to [0, hi], NaN to 0 so that no NaN becomes an index.
float clamp_coord(float v, float hi) {
  return v > 0.0 ? (v < hi ? v : hi) : 0.0;
}

float resoct_sample_cache(uint cache_slot, vec3 pos) {
  precise float cx = clamp_coord(pos.x - 0.5, float(PADDED_X - 1));
  precise float cy = clamp_coord(pos.y - 0.5, float(PADDED_Y - 1));
  precise float cz = clamp_coord(pos.z - 0.5, float(PADDED_Z - 1));
  int x0 = min(int(cx), max(PADDED_X - 2, 0));
  int y0 = min(int(cy), max(PADDED_Y - 2, 0));
  int z0 = min(int(cz), max(PADDED_Z - 2, 0));
  uint dx = x0 + 1 < PADDED_X ? 1u : 0u;
  uint dy = y0 + 1 < PADDED_Y ? uint(PADDED_X) : 0u;
  uint dz = z0 + 1 < PADDED_Z ? uint(PADDED_X * PADDED_Y) : 0u;
  precise float fx = cx - float(x0);
  precise float fy = cy - float(y0);
  precise float fz = cz - float(z0);
  uint chunk = cache_slot / pc.slots_per_chunk;
  uint i = (cache_slot - chunk * pc.slots_per_chunk) * uint(PADDED_X * PADDED_Y * PADDED_Z) +
           (uint(z0) * uint(PADDED_Y) + uint(y0)) * uint(PADDED_X) + uint(x0);
  float v000, v100, v010, v110, v001, v101, v011, v111;
  if (CACHE_CHUNKS == 1u) {
    RESOCT_LOAD_CELL(cache0);
  } else {
    switch (chunk) {
      case 0u: RESOCT_LOAD_CELL(cache0); break;
      case 1u: RESOCT_LOAD_CELL(cache1); break;
      case 2u: RESOCT_LOAD_CELL(cache2); break;
      case 3u: RESOCT_LOAD_CELL(cache3); break;
      case 4u: RESOCT_LOAD_CELL(cache4); break;
      case 5u: RESOCT_LOAD_CELL(cache5); break;
      case 6u: RESOCT_LOAD_CELL(cache6); break;
      default: RESOCT_LOAD_CELL(cache7); break;
    }
  }
  precise float c00 = v000 + fx * (v100 - v000);
  precise float c10 = v010 + fx * (v110 - v010);
  precise float c01 = v001 + fx * (v101 - v001);
  precise float c11 = v011 + fx * (v111 - v011);
  precise float c0 = c00 + fy * (c10 - c00);
  precise float c1 = c01 + fy * (c11 - c01);
  precise float c = c0 + fz * (c1 - c0);
  return c;
}

// RequestSet::insert on the device: linear probing from resoct_request_key_hash, at most
// max_probes slots, claim with compare-and-swap, hits by atomicAdd, refusals counted.
void brick_insert(uint key) {
  if (key != RESOCT_REQUEST_KEY_NONE) {
    uint i = resoct_request_key_hash(key, pc.brick_log2_capacity);
    for (uint probe = 0u; probe < pc.brick_max_probes; ++probe) {
      uint prev = atomicCompSwap(brick_req[i], RESOCT_REQUEST_KEY_NONE, key);
      if (prev == RESOCT_REQUEST_KEY_NONE || prev == key) {
        atomicAdd(brick_req[pc.brick_capacity + i], 1u);
        return;
      }
      i = (i + 1u) & (pc.brick_capacity - 1u);
    }
  }
  g_brick_dropped += 1u;
}

void node_insert(uint key) {
  if (key != RESOCT_REQUEST_KEY_NONE) {
    uint i = resoct_request_key_hash(key, pc.node_log2_capacity);
    for (uint probe = 0u; probe < pc.node_max_probes; ++probe) {
      uint prev = atomicCompSwap(node_req[i], RESOCT_REQUEST_KEY_NONE, key);
      if (prev == RESOCT_REQUEST_KEY_NONE || prev == key) {
        atomicAdd(node_req[pc.node_capacity + i], 1u);
        return;
      }
      i = (i + 1u) & (pc.node_capacity - 1u);
    }
  }
  g_node_dropped += 1u;
}

void resoct_report_request(uint device_key) {
  brick_insert(device_key);
}
void resoct_report_node_request(uint node) {
  node_insert(node);
}
void resoct_mark_used(uint cache_slot) {
  uint bit = 1u << (cache_slot & 31u);
  // Read first: almost every call finds the bit set already.
  if ((used_bits[cache_slot >> 5u] & bit) == 0u) atomicOr(used_bits[cache_slot >> 5u], bit);
}

#include "resoct/kernel/traverse.glsl.h"

// One step of the tree reduction: lanes [0, s) add lanes [s, 2s) where those exist. Written out
// per step rather than as a loop: lavapipe's loop guard (see main) could end a loop early in some
// lanes, and a barrier inside a loop must be reached by every invocation the same number of
// times. `WORKGROUP > s` is a specialization constant, so unused steps compile away.
#define RESOCT_REDUCE_STEP(s)                                            \
  if (WORKGROUP > (s)) {                                                 \
    if (lid < (s) && lid + (s) < WORKGROUP) {                            \
      [[unroll]] for (uint k = 0u; k < STAT_COUNT; ++k) {                \
        partial[k][lid] = add64(partial[k][lid], partial[k][lid + (s)]); \
      }                                                                  \
    }                                                                    \
    memoryBarrierShared();                                               \
    barrier();                                                           \
  }

void main() {
  uvec2 px = gl_GlobalInvocationID.xy;
  uint counts[STAT_COUNT];
  [[unroll]] for (uint k = 0u; k < STAT_COUNT; ++k) counts[k] = 0u;
  // No early return: every invocation takes part in the reduction's barriers.
  if (px.x < frame.width && px.y < frame.height) {
    ResoctRayStats st;
    // RESOCT_EFFECTS (constant_id 30, kernel/effects.glsl.h) selects the effect specialization.
    vec4 p = resoct_render_pixel_fx(frame, px.x, px.y, st);
    // lavapipe ends every loop of an invocation once 65535 loop back-edges were taken in total
    // (a driver guard against endless loops), which would cut a long ray short without a trace.
    // This loop's trip count is unknown at compile time, so it stays a loop: it runs twice unless
    // the guard has fired, and then the ray counts as stopped by the iteration cap.
    uint canary = 0u;
    for (uint i = 0u; i < 2u + (frame.width >> 31u); ++i) canary += 1u;
    if (canary < 2u) st.cap_hits = 1u;
    // The image holds straight alpha, as the CPU backend writes it.
    pixels[px.y * frame.width + px.x] = p.a > 0.0 ? vec4(p.rgb / p.a, p.a) : vec4(0.0);
    counts[STAT_SAMPLES] = st.samples;
    counts[STAT_NODES] = st.nodes;
    counts[STAT_ACCESSES] = st.brick_accesses;
    counts[STAT_ITERATIONS] = st.iterations;
    counts[STAT_CAPS] = st.cap_hits;
    counts[STAT_REQUESTS] = st.requests;
    counts[STAT_BRICK_DROPPED] = g_brick_dropped;
    counts[STAT_NODE_DROPPED] = g_node_dropped;
    counts[STAT_SKIPPED] = uint(round(st.skipped * DISTANCE_SCALE));
    counts[STAT_MARCHED] = uint(round(st.marched * DISTANCE_SCALE));
    counts[STAT_GRADIENTS] = st.gradient_evals;
    counts[STAT_SHADOW_RAYS] = st.shadow_rays;
  }
  uint lid = gl_LocalInvocationIndex;
  [[unroll]] for (uint k = 0u; k < STAT_COUNT; ++k) partial[k][lid] = uvec2(counts[k], 0u);
  memoryBarrierShared();
  barrier();
  // Workgroups of up to 1024 invocations (Vulkan's guaranteed maximum).
  RESOCT_REDUCE_STEP(512u)
  RESOCT_REDUCE_STEP(256u)
  RESOCT_REDUCE_STEP(128u)
  RESOCT_REDUCE_STEP(64u)
  RESOCT_REDUCE_STEP(32u)
  RESOCT_REDUCE_STEP(16u)
  RESOCT_REDUCE_STEP(8u)
  RESOCT_REDUCE_STEP(4u)
  RESOCT_REDUCE_STEP(2u)
  RESOCT_REDUCE_STEP(1u)
  if (lid == 0u) {
    [[unroll]] for (uint k = 0u; k < STAT_COUNT; ++k) stat_add64(k, partial[k][0]);
  }
}
