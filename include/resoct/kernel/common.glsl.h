// resoct single-source kernel: the bridge between C++ (with GLM) and GLSL.
//
// Every include/resoct/kernel/*.glsl.h is written in the common subset of C++20 and GLSL 4.50 and
// includes this file first. In C++ the kernel lives in namespace resoct::kernel with GLM's
// vector types and functions in scope; in GLSL it is global. Write only what both languages
// accept: no pointers, references, templates or classes; no implicit int/uint/float conversions
// (GLSL rejects them); literals with explicit suffixes (1u, 1.0f); structs of scalars only.
//
// Portable spellings:
//   RESOCT_FN                 before every function: `inline` in C++, nothing in GLSL
//   RESOCT_OUT(T), RESOCT_INOUT(T)   parameter qualifiers: T& in C++, out/inout T in GLSL
//   RESOCT_CONST(T, name, v)  a compile-time constant visible to both languages
//   RESOCT_KERNEL_BEGIN / _END     open and close namespace resoct::kernel in C++ only
#ifndef RESOCT_KERNEL_COMMON_GLSL_H
#define RESOCT_KERNEL_COMMON_GLSL_H

#ifdef __cplusplus
#include <cstdint>

#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>

namespace resoct::kernel {
using namespace glm;
using uint = std::uint32_t;

// GLSL built-ins that GLM spells differently or lacks.
inline float uintBitsToFloat(uint v) {
  return glm::uintBitsToFloat(v);
}
inline uint floatBitsToUint(float v) {
  return glm::floatBitsToUint(v);
}
// floor() without SSE4.1 (the x86-64 baseline) is a libm-style sequence of ~17 instructions;
// the kernel's positions are far below 2^31, where truncation plus a correction is exact. Floats
// of magnitude 2^23 and above (and NaN) are integral or meaningless and returned as they are.
inline float resoct_floor1(float x) {
  if (!(x > -8388608.0f && x < 8388608.0f)) return x;
  const float r = float(int(x));
  return r > x ? r - 1.0f : r;
}
inline float resoct_ceil(float x) {
  return -resoct_floor1(-x);
}
inline vec3 resoct_floor(vec3 v) {
  return vec3(resoct_floor1(v.x), resoct_floor1(v.y), resoct_floor1(v.z));
}
inline int findLSB(uint v) {
  return v == 0u ? -1 : __builtin_ctz(v);
}
inline int findMSB(uint v) {
  return v == 0u ? -1 : 31 - __builtin_clz(v);
}
// Without -mpopcnt (the x86-64 baseline) __builtin_popcount is a library call; this is a dozen
// inline instructions.
inline int bitCount(uint v) {
  v = v - ((v >> 1) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
  return int((((v + (v >> 4)) & 0x0F0F0F0Fu) * 0x01010101u) >> 24);
}
}  // namespace resoct::kernel

#define RESOCT_FN inline
#define RESOCT_OUT(T) T&
#define RESOCT_INOUT(T) T&
#define RESOCT_CONST(T, name, value) inline constexpr T name = value
#define RESOCT_KERNEL_BEGIN namespace resoct::kernel {
#define RESOCT_KERNEL_END }
// Read-only frame parameter: by reference in C++ (no copy of the 520-byte record per call), by
// value in GLSL.
#define RESOCT_FRAME_IN const ResoctFrame&
// A read-only record, as a parameter or as a local bound to a table entry (resoct_read_slot,
// resoct_read_depth, resoct_read_level): by reference in C++, by value in GLSL. A by-value copy
// per call or read cost 2 % of the residency march's instructions (bench/README.md).
#define RESOCT_IN(T) const T&
// A hot inner loop kept out of its caller in C++, so that the loop's registers are allocated for
// the loop alone and not for the whole march around it (GLSL compilers inline it as usual).
#define RESOCT_LOOP_FN [[gnu::noinline, gnu::flatten]] inline
// Results that decide segment boundaries (slices, lens): `precise` in GLSL so that the device
// does not contract them into fused multiply-adds (the CPU build never does), keeping iteration
// counts identical between backends.
#define RESOCT_PRECISE
#else
#define resoct_floor(x) floor(x)
#define resoct_ceil(x) ceil(x)
#define RESOCT_FN
#define RESOCT_OUT(T) out T
#define RESOCT_INOUT(T) inout T
#define RESOCT_CONST(T, name, value) const T name = value
#define RESOCT_KERNEL_BEGIN
#define RESOCT_KERNEL_END
#define RESOCT_FRAME_IN ResoctFrame
#define RESOCT_IN(T) T
#define RESOCT_LOOP_FN
#define RESOCT_PRECISE precise
#endif

#endif  // RESOCT_KERNEL_COMMON_GLSL_H
