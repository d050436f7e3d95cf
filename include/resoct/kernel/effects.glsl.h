// resoct kernel: effect specialization (docs/architecture.md §4) and Blinn-Phong shading.
//
// A scene's effects and channel modes form a bit mask, RESOCT_EFFECTS. The kernel code that
// depends on it is written once and specialized per mask:
//   C++   RESOCT_EFFECTS is a template parameter of every RESOCT_FX_FN function; branches on it
//         are `if constexpr`, so the mask-0 instantiation contains none of the effect code.
//   GLSL  RESOCT_EFFECTS is a specialization constant (constant_id RESOCT_EFFECTS_CONSTANT_ID),
//         so the driver folds the branches when it builds the pipeline variant of a mask.
// Spelling: declare with `RESOCT_FX_FN type name(...)`, call with `RESOCT_FX(name)(...)`, branch
// with `RESOCT_IF_FX(RESOCT_EFFECT_X) { ... }`; RESOCT_FX_PLAIN(name) is the mask-0 version in
// C++ and the specialization constant's in GLSL (whose default is 0). Code that never depends on
// the mask stays RESOCT_FN.
#ifndef RESOCT_KERNEL_EFFECTS_GLSL_H
#define RESOCT_KERNEL_EFFECTS_GLSL_H

#include "resoct/kernel/common.glsl.h"
#include "resoct/kernel/frame.glsl.h"

#ifdef __cplusplus
#define RESOCT_FX_FN             \
  template <uint RESOCT_EFFECTS> \
  inline
#define RESOCT_FX(name) name<RESOCT_EFFECTS>
#define RESOCT_IF_FX(bit) if constexpr ((RESOCT_EFFECTS & (bit)) != 0u)
#define RESOCT_FX_PLAIN(name) name<0u>
#else
#ifndef RESOCT_EFFECTS_CONSTANT_ID
#define RESOCT_EFFECTS_CONSTANT_ID 30
#endif
layout(constant_id = RESOCT_EFFECTS_CONSTANT_ID) const uint RESOCT_EFFECTS = 0u;
#define RESOCT_FX_FN
#define RESOCT_FX(name) name
#define RESOCT_IF_FX(bit) if ((RESOCT_EFFECTS & (bit)) != 0u)
#define RESOCT_FX_PLAIN(name) name
#endif

RESOCT_KERNEL_BEGIN

// Effect bits. SHADING and SHADOWS come from the scene's "effects"; ISO and PROJECTION are set
// when any channel has mode "iso", respectively "mip" or "aip"; PREINT by the scene's
// "preintegration" (kernel/preintegration.glsl.h).
RESOCT_CONST(uint, RESOCT_EFFECT_SHADING, 1u);
RESOCT_CONST(uint, RESOCT_EFFECT_SHADOWS, 2u);
RESOCT_CONST(uint, RESOCT_EFFECT_ISO, 4u);
RESOCT_CONST(uint, RESOCT_EFFECT_PROJECTION, 8u);
RESOCT_CONST(uint, RESOCT_EFFECT_PREINT, 16u);
/// Masks run 0 .. RESOCT_EFFECT_MASKS - 1 (the CPU backend instantiates each).
RESOCT_CONST(uint, RESOCT_EFFECT_MASKS, 32u);
/// The bits whose code runs per channel value in the effect path (resoct_fx_channel).
/// Pre-integration alone only changes the DVR lookup and stays on the plain path.
RESOCT_CONST(uint, RESOCT_EFFECT_ANY, 15u);

// The render mode as part of a C++ specialization: bits RESOCT_EFFECT_MODE_SHIFT and up of a
// mask hold the mode + 1 (RESOCT_MODE_*), 0 meaning "the frame's mode, at run time". The CPU
// backend instantiates its plain kernel once per mode, so that a residency frame's code holds no
// page-table or octree branch (fewer live values across the march loop, measured with
// callgrind: bench/README.md "Fifteenth pass"). GLSL always reads the frame's mode.
RESOCT_CONST(uint, RESOCT_EFFECT_MODE_SHIFT, 8u);
// Likewise a frame of one channel (ResoctFrame.slot_count == 1): the channel loops then run
// once by construction.
RESOCT_CONST(uint, RESOCT_EFFECT_ONE_SLOT, 128u);
#ifdef __cplusplus
/// The mask of effects `effects` specialized for render mode `mode`.
constexpr uint resoct_fx_with_mode(uint effects, uint mode) {
  return effects | ((mode + 1u) << RESOCT_EFFECT_MODE_SHIFT);
}
/// The mode a specialization was compiled for, else `frame_mode`.
template <uint E>
constexpr uint resoct_fx_mode(uint frame_mode) {
  return (E >> RESOCT_EFFECT_MODE_SHIFT) != 0u ? (E >> RESOCT_EFFECT_MODE_SHIFT) - 1u : frame_mode;
}
/// The channels of a frame (ResoctFrame.slot_count, at most RESOCT_MAX_SLOTS): 1 in a
/// RESOCT_EFFECT_ONE_SLOT specialization.
template <uint E>
constexpr uint resoct_fx_slot_count(uint frame_slots) {
  return (E & RESOCT_EFFECT_ONE_SLOT) != 0u ? 1u : min(frame_slots, RESOCT_MAX_SLOTS);
}
/// Whether a specialization carries error-bounded LOD (kernel/error_lod.glsl.h): every kernel
/// except the plain ones specialized per mode, which frames that use it never run (the CPU
/// backend gives them the plain kernel of mask 0), so that its checks cost those nothing.
template <uint E>
constexpr bool resoct_fx_error_lod() {
  return (E >> RESOCT_EFFECT_MODE_SHIFT) == 0u;
}
#define RESOCT_FX_MODE(f) resoct_fx_mode<RESOCT_EFFECTS>((f).mode)
#define RESOCT_FX_SLOT_COUNT(f) resoct_fx_slot_count<RESOCT_EFFECTS>((f).slot_count)
#define RESOCT_FX_ERROR_LOD (resoct_fx_error_lod<RESOCT_EFFECTS>())
#else
#define RESOCT_FX_MODE(f) ((f).mode)
#define RESOCT_FX_SLOT_COUNT(f) min((f).slot_count, RESOCT_MAX_SLOTS)
#define RESOCT_FX_ERROR_LOD true
#endif

// Channel modes (ResoctSlotInfo.mode).
RESOCT_CONST(uint, RESOCT_CHANNEL_DVR, 0u);
RESOCT_CONST(uint, RESOCT_CHANNEL_ISO, 1u);
RESOCT_CONST(uint, RESOCT_CHANNEL_MIP, 2u);
RESOCT_CONST(uint, RESOCT_CHANNEL_AIP, 3u);
RESOCT_CONST(uint, RESOCT_MAX_ISOVALUES, 4u);

// Light kinds (ResoctFrame.light_kind).
RESOCT_CONST(uint, RESOCT_LIGHT_HEADLIGHT, 0u);
RESOCT_CONST(uint, RESOCT_LIGHT_DIRECTIONAL, 1u);
RESOCT_CONST(uint, RESOCT_LIGHT_POINT, 2u);

/// Shaded DVR samples cast a shadow ray only above this corrected opacity: fainter samples
/// change the pixel by less than one 8-bit step whatever their shadow.
RESOCT_CONST(float, RESOCT_SHADOW_MIN_ALPHA, 0.00390625f);

/// The frame constants the effect code needs, gathered once per ray (passing ResoctFrame by
/// value to non-inlined helpers would copy it per call on the CPU).
struct ResoctFxParams {
  uint light_kind;
  float light_x;
  float light_y;
  float light_z;
  float ambient;
  float diffuse;
  float specular;
  float shininess;
  uint gradient_forward;
  uint shadow_lod_shift;
  float vpb_x;  // level-0 voxels per box unit
  float vpb_y;
  float vpb_z;
  uint extent_x;  // level-0 extent
  uint extent_y;
  uint extent_z;
  float step_scale;
  float min_step;
  float ref_step;
  float ert_opacity;
  uint start_depth;
  uint depth_count;
  uint max_iterations;
};

RESOCT_FN ResoctFxParams resoct_fx_params(RESOCT_FRAME_IN f, ResoctFxFrame e) {
  ResoctFxParams p;
  p.light_kind = e.light_kind;
  p.light_x = e.light_x;
  p.light_y = e.light_y;
  p.light_z = e.light_z;
  p.ambient = e.ambient;
  p.diffuse = e.diffuse;
  p.specular = e.specular;
  p.shininess = e.shininess;
  p.gradient_forward = e.gradient_forward;
  p.shadow_lod_shift = e.shadow_lod_shift;
  p.vpb_x = f.voxels_per_box_x;
  p.vpb_y = f.voxels_per_box_y;
  p.vpb_z = f.voxels_per_box_z;
  p.extent_x = f.extent_x;
  p.extent_y = f.extent_y;
  p.extent_z = f.extent_z;
  p.step_scale = f.step_scale;
  p.min_step = f.min_step;
  p.ref_step = f.ref_step;
  p.ert_opacity = f.ert_opacity;
  p.start_depth = f.start_depth;
  p.depth_count = f.depth_count;
  p.max_iterations = f.max_iterations;
  return p;
}

RESOCT_FN vec3 resoct_fx_voxels_per_box(RESOCT_IN(ResoctFxParams) p) {
  return vec3(p.vpb_x, p.vpb_y, p.vpb_z);
}

/// Unit vector from a box-space position toward the light. The headlight shines along the view
/// ray, so it points back along `view_dir`.
RESOCT_FN vec3 resoct_light_vector(RESOCT_IN(ResoctFxParams) p, vec3 pos_box, vec3 view_dir) {
  if (p.light_kind == RESOCT_LIGHT_DIRECTIONAL) return -vec3(p.light_x, p.light_y, p.light_z);
  if (p.light_kind == RESOCT_LIGHT_POINT) {
    vec3 d = vec3(p.light_x, p.light_y, p.light_z) - pos_box;
    float len = length(d);
    return len > 0.0f ? d / len : -view_dir;
  }
  return -view_dir;
}

/// Blinn-Phong with a two-sided normal: `gradient` (box space) of the normalized field, `light`
/// unit vector toward the light, `view_dir` unit ray direction, `shadow` transmittance toward
/// the light in [0, 1] (scales diffuse and specular, not ambient). A zero gradient has no
/// normal: the colour is returned unshaded. Channels are clamped to [0, 1].
RESOCT_FN vec3 resoct_blinn_phong(RESOCT_IN(ResoctFxParams) p, vec3 rgb, vec3 gradient, vec3 light,
                                  vec3 view_dir, float shadow) {
  float g2 = dot(gradient, gradient);
  if (!(g2 > 0.0f)) return rgb;
  // The normal points toward lower values (out of dense material), turned toward the viewer.
  vec3 n = -gradient * (1.0f / sqrt(g2));
  vec3 v = -view_dir;
  if (dot(n, v) < 0.0f) n = -n;
  float ndl = max(dot(n, light), 0.0f);
  vec3 h = light + v;
  float hl = length(h);
  float spec = 0.0f;
  if (hl > 0.0f && ndl > 0.0f) spec = pow(max(dot(n, h / hl), 0.0f), p.shininess);
  vec3 c = rgb * (p.ambient + p.diffuse * ndl * shadow) + vec3(p.specular * spec * shadow);
  return clamp(c, vec3(0.0f), vec3(1.0f));
}

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_EFFECTS_GLSL_H
