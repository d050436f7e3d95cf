#version 450
// resoct Vulkan backend: applies (index, value) word deltas to a device array (page table or
// octree words). The host removes duplicate indices first (the last delta of an index wins), so
// invocations never write the same word and the order of writes does not matter.

layout(local_size_x_id = 0, local_size_y = 1, local_size_z = 1) in;

layout(push_constant) uniform Push {
  uint first_word;  // where the pairs start in the staging ring, in 32-bit words
  uint count;       // pairs in this dispatch
  uint dst_words;   // length of the target array (the host checked every index already)
}
pc;

layout(std430, binding = 0) readonly buffer Pairs {
  uint pairs[];
};
layout(std430, binding = 1) writeonly buffer Target {
  uint target[];
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  uint index = pairs[pc.first_word + 2u * i];
  uint value = pairs[pc.first_word + 2u * i + 1u];
  if (index < pc.dst_words) target[index] = value;
}
