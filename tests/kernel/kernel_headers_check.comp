#version 450
#extension GL_GOOGLE_include_directive : require
// Compiles the single-source kernel headers as GLSL and calls every encode/decode function so that
// glslang type-checks them (unused functions are not checked in depth).
#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Pages {
  uint pages[];
};
layout(std430, binding = 1) buffer OutWords {
  uint words[];
};
layout(std430, binding = 2) buffer OutValues {
  float values[];
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint e = pages[i];
  uint acc = resoct_page_state(e) + resoct_page_payload(e) + resoct_page_cache_slot(e);
  if (resoct_page_is_mapped(e) || resoct_page_is_constant(e)) acc += 1u;
  acc += resoct_page_encode_mapped(i) ^ resoct_page_encode_homogeneous(i & 0xFFFFu) ^
         RESOCT_PAGE_EMPTY_WORD;
  acc += resoct_page_local_index(uvec3(i, 1u, 2u), uvec3(64u, 4u, 4u));
  acc += resoct_page_block_index(uvec3(i, 17u, 2u), uvec3(64u, 40u, 4u)) +
         resoct_page_in_block_index(uvec3(i, 1u, 2u)) + resoct_page_blocks(uvec3(i)).x;
  uint key = resoct_request_key_brick(resoct_request_table_id(1u, 2u, 8u), i);
  if (resoct_request_key_is_block_miss(key)) key = resoct_request_key_block_miss(i);
  acc += resoct_request_key_pool_block(key) + resoct_request_key_in_block(key) +
         resoct_request_key_directory(key) + resoct_request_key_hash(key, 12u);
  if (key == RESOCT_REQUEST_KEY_NONE) acc = 0u;
  words[i] = acc;
  values[i] = resoct_page_homogeneous_value(e);
}
