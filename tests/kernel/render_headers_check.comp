#version 450
// Compile check: the render kernel headers are valid GLSL 4.50
// (tests/core/kernel/test_render_kernel_glsl.cpp runs glslangValidator on this file). Every
// function is called so that it is type-checked.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 1) in;

layout(std430, binding = 0) readonly buffer TfLuts {
  vec4 tf_entries[];
};
layout(std430, binding = 1) readonly buffer LevelSizes {
  float level_size_log2[];
};
layout(std430, binding = 2) buffer Out {
  vec4 results[];
};

vec4 resoct_read_tf(uint slot, uint index) {
  return tf_entries[slot * 1024u + index];
}
float resoct_read_level_size_log2(uint level) {
  return level_size_log2[level];
}

#include "resoct/kernel/ray.glsl.h"
#include "resoct/kernel/step.glsl.h"
#include "resoct/kernel/tf.glsl.h"
#include "resoct/kernel/composite.glsl.h"

void main() {
  vec3 origin = vec3(-1.0f, 0.5f, 0.0f);
  vec3 dir = vec3(1.0f, 0.0f, -0.0f);
  vec2 tt = resoct_ray_box(origin, dir, vec3(0.0f), vec3(1.0f));
  bool hit = resoct_ray_hits(tt, 0.0f);
  ivec3 cell = ivec3(1048000, 3, 7);
  vec3 frac = vec3(1.25f, -0.5f, 0.0f);
  resoct_split_normalize(cell, frac);
  vec3 rel = resoct_relative_origin(cell, frac, ivec3(1048000, 0, 0));
  vec2 tn = resoct_ray_node_local(rel, resoct_ray_inverse(dir), vec3(16.0f));

  float dt = resoct_step_size(dir, vec3(1.0f / 256.0f), 1.0f, 1.0e-6f);
  float t = resoct_advance_t(tt.x, resoct_segment_length(tt.x, dt, tt.y));
  float fp = resoct_pixel_footprint(0.0f, 0.01f, t);
  float budget = resoct_lod_budget_log2(0.0f, 0.01f, t, 1.0f);
  uint lod = resoct_lod_level(budget, 9u);
  uint level = resoct_channel_level(lod, 0u, 15u);

  float v = resoct_normalize_value(128.0f, 0.0f, 1.0f / 255.0f);
  vec4 c = resoct_tf_lookup(0u, v);
  if (!resoct_tf_range_visible(0xF0u, 0.1f, v)) c = vec4(resoct_occupancy_bin(v));
  float a = resoct_correct_opacity(c.a, dt * 256.0f);
  vec4 weighted;
  float combined;
  resoct_mix_begin(weighted, combined);
  resoct_mix_add(weighted, combined, c.rgb, a);
  vec4 s = resoct_mix_result(weighted, combined);
  vec4 acc = resoct_composite(vec4(0.0f), s);
  if (resoct_saturated(acc, 0.99f)) acc = resoct_unpremultiply(acc);
  acc = resoct_over_background(acc, vec4(0.0f, 0.0f, 0.0f, 1.0f));
  vec4 pre = resoct_premultiply(c.rgb, a);

  results[0] = vec4(tt, tn);
  results[1] = vec4(rel, hit ? 1.0f : 0.0f);
  results[2] = vec4(fp, budget, float(level), resoct_log_one_minus(0.5f));
  results[3] = acc + pre + vec4(resoct_one_minus_exp(-0.5f));
}
