#version 450
// Compile check: the traversal kernel is valid GLSL 4.50 (tests/core/kernel/test_traverse_glsl.cpp
// runs glslangValidator on this file). Defines every accessor over storage buffers, includes
// the kernel and renders one pixel per invocation.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 8, local_size_y = 8) in;

#include "resoct/kernel/frame.glsl.h"

layout(std430, binding = 0) readonly buffer Frame {
  ResoctFrame frame;
  ResoctFxFrame fx_frame;
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
layout(std430, binding = 5) readonly buffer Pages {
  uint pages[];
};
layout(std430, binding = 6) readonly buffer DirectoryOffsets {
  uint directory_offsets[];
};
layout(std430, binding = 14) readonly buffer Directory {
  uint directory[];
};
layout(std430, binding = 7) readonly buffer TfLuts {
  vec4 tf_entries[];
};
layout(std430, binding = 21) readonly buffer PreintTables {
  vec4 preint_entries[];
};
layout(std430, binding = 22) readonly buffer StepLuts {
  vec4 step_lut_entries[];
};
layout(std430, binding = 23) readonly buffer VisibleSubtrees {
  uint visible_subtree_words[];
};
layout(std430, binding = 8) readonly buffer Cache {
  float cache_voxels[];
};
layout(std430, binding = 9) buffer Requests {
  uint request_count;
  uint request_keys[];
};
layout(std430, binding = 10) buffer NodeRequests {
  uint node_request_count;
  uint node_keys[];
};
layout(std430, binding = 11) buffer Used {
  uint used_bits[];
};
layout(std430, binding = 12) buffer Out {
  vec4 pixels[];
};
layout(std430, binding = 13) buffer Stats {
  uint stat_samples;
  uint stat_caps;
};

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

float cache_voxel(uint cache_slot, ivec3 v) {
  uint px = frame.padded_x;
  uint py = frame.padded_y;
  uint pz = frame.padded_z;
  uvec3 c = uvec3(clamp(v, ivec3(0), ivec3(px - 1u, py - 1u, pz - 1u)));
  return cache_voxels[cache_slot * px * py * pz + (c.z * py + c.y) * px + c.x];
}

float resoct_sample_cache(uint cache_slot, vec3 pos) {
  vec3 p = pos - vec3(0.5f);
  ivec3 i0 = ivec3(floor(p));
  vec3 w = p - vec3(i0);
  float c000 = cache_voxel(cache_slot, i0);
  float c100 = cache_voxel(cache_slot, i0 + ivec3(1, 0, 0));
  float c010 = cache_voxel(cache_slot, i0 + ivec3(0, 1, 0));
  float c110 = cache_voxel(cache_slot, i0 + ivec3(1, 1, 0));
  float c001 = cache_voxel(cache_slot, i0 + ivec3(0, 0, 1));
  float c101 = cache_voxel(cache_slot, i0 + ivec3(1, 0, 1));
  float c011 = cache_voxel(cache_slot, i0 + ivec3(0, 1, 1));
  float c111 = cache_voxel(cache_slot, i0 + ivec3(1, 1, 1));
  float c00 = mix(c000, c100, w.x);
  float c10 = mix(c010, c110, w.x);
  float c01 = mix(c001, c101, w.x);
  float c11 = mix(c011, c111, w.x);
  return mix(mix(c00, c10, w.y), mix(c01, c11, w.y), w.z);
}

void resoct_report_request(uint device_key) {
  uint i = atomicAdd(request_count, 1u);
  request_keys[i] = device_key;
}
void resoct_report_node_request(uint node) {
  uint i = atomicAdd(node_request_count, 1u);
  node_keys[i] = node;
}
void resoct_mark_used(uint cache_slot) {
  atomicOr(used_bits[cache_slot >> 5u], 1u << (cache_slot & 31u));
}

#include "resoct/kernel/traverse.glsl.h"

void main() {
  uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= frame.width || px.y >= frame.height) return;
  ResoctRayStats stats;
  vec4 c = resoct_render_pixel(frame, px.x, px.y, stats);
  pixels[px.y * frame.width + px.x] = c;
  atomicAdd(stat_samples, stats.samples);
  atomicAdd(stat_caps, stats.cap_hits);
}
