// resoct single-source kernel: the per-frame records every backend hands to the traversal.
//
// All records are structs of 4-byte scalars only, so their std430 layout equals the C++ layout
// (no vec3 padding). The host fills them (src/core/render/frame_tables.cpp); the CPU backend reads
// them directly, the Vulkan backend uploads them to storage buffers.
//
// Coordinate systems (see docs/rendering.md):
//   box space      the volume's normalized physical box: min corner at the origin, the longest
//                  physical axis spans [0, 1]. Cameras, steps, footprints and t live here.
//   voxel space    level-0 voxel coordinates: voxel i spans [i, i + 1) per axis. Octree nodes
//                  and bricks are integer boxes here. A box-space vector v is v * voxels_per_box.
// Precision: a voxel-space position is kept as an exact integer cell (ivec3) plus a float
// offset relative to it, starting from the eye (eye_cell + eye_frac), so that a 2^20-voxel axis
// samples correctly near the camera. Nothing global is stored as a normalized float.
#ifndef RESOCT_KERNEL_FRAME_GLSL_H
#define RESOCT_KERNEL_FRAME_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

// RenderMode (frame.mode): the three methods of paper 000 Table 1 in one kernel.
RESOCT_CONST(uint, RESOCT_MODE_RESIDENCY, 0u);  // residency octree (default)
RESOCT_CONST(uint, RESOCT_MODE_PAGETABLE, 1u);  // page table only, no substitution
RESOCT_CONST(uint, RESOCT_MODE_OCTREE, 2u);     // standard octree, one brick per node

RESOCT_CONST(uint, RESOCT_PROJECTION_PERSPECTIVE, 0u);
RESOCT_CONST(uint, RESOCT_PROJECTION_ORTHOGRAPHIC, 1u);

// Most visible slots one frame may hold (bounds per-ray arrays in the kernel).
RESOCT_CONST(uint, RESOCT_MAX_SLOTS, 32u);
// Most slice planes one frame may hold (kernel/slice.glsl.h).
RESOCT_CONST(uint, RESOCT_MAX_SLICES, 4u);

// Per-frame constants.
struct ResoctFrame {
  // Output and configuration.
  uint width;            // pixels
  uint height;           // pixels
  uint mode;             // RESOCT_MODE_*
  uint slot_count;       // entries of the slot table (visible channels, importance order)
  uint level_count;      // brick hierarchy levels
  uint depth_count;      // octree depths (root = 0)
  uint start_depth;      // traversal starts here (clamped to depth_count - 1)
  uint max_iterations;   // hard cap of march iterations per ray; hits are counted
  uint projection;       // RESOCT_PROJECTION_*
  uint frame_index;      // host frame counter
  uint page_slot_count;  // slots of the page table and octree (>= the visible ones)
  uint node_slot_count;  // slots per octree node record (== page_slot_count)

  // Camera in box space: orthonormal basis, eye position.
  float eye_x;
  float eye_y;
  float eye_z;
  float forward_x;
  float forward_y;
  float forward_z;
  float right_x;
  float right_y;
  float right_z;
  float up_x;
  float up_y;
  float up_z;
  float half_height;  // perspective: tan(fov / 2); orthographic: view height / 2 in box units
  float aspect;       // width / height

  // The eye in voxel space, split into an exact cell and a fraction in [0, 1).
  int eye_cell_x;
  int eye_cell_y;
  int eye_cell_z;
  float eye_frac_x;
  float eye_frac_y;
  float eye_frac_z;
  // Level-0 voxels per box unit along each axis (1 / voxel size in box units).
  float voxels_per_box_x;
  float voxels_per_box_y;
  float voxels_per_box_z;

  // Volume and bricks (voxel space).
  uint extent_x;  // level-0 voxels per axis (< 2^31)
  uint extent_y;
  uint extent_z;
  uint brick_x;  // brick core size per axis
  uint brick_y;
  uint brick_z;
  uint halo;      // ghost voxels per side
  uint padded_x;  // brick + 2 halo
  uint padded_y;
  uint padded_z;

  // Sampling (box space).
  float finest_voxel_x;  // voxel size of the finest level any visible channel may use
  float finest_voxel_y;
  float finest_voxel_z;
  float step_scale;      // scene step_scale
  float min_step;        // floor of the step so every iteration advances
  float ref_step;        // Δ₀: the step transfer-function alpha refers to
  float footprint_base;  // pixel footprint at depth z: base + slope * z
  float footprint_slope;
  float lod_error_px;
  float ert_opacity;
  float background_r;  // straight alpha
  float background_g;
  float background_b;
  float background_a;

  // Request strategy (paper 002 §5.3.2): 0 = global (only the target brick of a missing sample),
  // 1 = greedy (the target and every coarser level's brick at the sample position up to the
  // first one that is present or the channel's coarsest level). Added by the traversal kernel.
  uint request_greedy;

  // Slices and lens (kernel/slice.glsl.h, kernel/lens.glsl.h), all zero when the scene has none.
  // Positions are split like the eye (exact level-0 cell + fraction); vectors are in voxel space.
  uint slice_count;                            // planes in use, <= RESOCT_MAX_SLICES
  uint lens_enabled;                           // 1: the slot table holds a second bank
  int slice_cell[3u * RESOCT_MAX_SLICES];      // point on plane i: cell (x, y, z) at 3i
  float slice_frac[3u * RESOCT_MAX_SLICES];    //   and fraction in [0, 1)
  float slice_normal[3u * RESOCT_MAX_SLICES];  // unit plane normal in voxel space
  float slice_window[RESOCT_MAX_SLICES];       // > 0: window/level grey; 0: transfer function
  float slice_level[RESOCT_MAX_SLICES];        // normalized value shown as grey 1/2
  uint slice_channels[RESOCT_MAX_SLICES];      // bit c: slot-table entry c is shown
  int lens_cell_x;                             // lens centre: cell and fraction
  int lens_cell_y;
  int lens_cell_z;
  float lens_frac_x;
  float lens_frac_y;
  float lens_frac_z;
  // Row i (at 3i): lens axis i / (voxels_per_box * half size i), so that a voxel-space offset
  // from the centre maps to lens coordinates, the lens being [-1, 1]^3.
  float lens_matrix[9];

  // Jitter for accumulating frames (docs/rendering.md "Jittered accumulation"); all 0 = none, and
  // then the image is bit-identical to a frame without jitter. Last, so that no other offset moves.
  float jitter_x;       // sub-pixel offset of every pixel's ray, pixels, in [-0.5, 0.5)
  float jitter_y;       //   (x to the right, y down, like pixel rows)
  float jitter_sample;  // shift of the march's samples along the ray, steps, in [-0.5, 0.5)

  // Step levels and their opacity-corrected LUTs (kernel/step_lut.glsl.h): a ray's full-step
  // ratio Δ/Δ₀ is rounded down to its bits >> step_level_shift; levels step_level_first ..
  // + step_level_count - 1 have tables. step_level_count = 0: none (per-sample correction).
  uint step_level_shift;
  uint step_level_first;
  uint step_level_count;
};

// Effect constants of a frame (kernel/effects.glsl.h; docs/rendering.md "Effects"), a record of
// their own: ResoctFrame is passed by value to many helpers of the plain kernel, and growing it
// changes how the C++ compiler inlines them. Read through resoct_read_fx_frame() only by the
// kernel specializations that use effects.
struct ResoctFxFrame {
  uint effects;     // RESOCT_EFFECT_* bits these tables were built for
  uint light_kind;  // RESOCT_LIGHT_*
  float light_x;    // directional: direction the light travels; point: position (box)
  float light_y;
  float light_z;
  float ambient;  // Blinn-Phong coefficients
  float diffuse;
  float specular;
  float shininess;
  uint gradient_forward;  // 1: forward differences (3 lookups), 0: central (6 lookups)
  uint shadow_lod_shift;  // shadow rays march the view LOD level + this (paper 004 §7.2)
};

// One visible channel, in importance order (slot table index 0 is traversed first).
struct ResoctSlotInfo {
  uint slot;          // page-table / octree slot this channel occupies
  uint finest_level;  // allowed level range, clamped to the hierarchy
  uint coarsest_level;
  uint vis_bins;   // occupancy bins where the transfer function is visible (alpha > 0)
  uint vis_lo16;   // visible normalized value range quantized like node min/max:
  uint vis_hi16;   //   lo rounded down, hi rounded up; vis_lo16 > vis_hi16 = never visible
  float range_lo;  // raw voxel value -> normalized: (raw - range_lo) * inv_range_width
  float inv_range_width;
  // Effects: RESOCT_CHANNEL_* mode and up to RESOCT_MAX_ISOVALUES normalized isovalues (iso).
  uint mode;
  uint iso_count;
  float iso0;
  float iso1;
  float iso2;
  float iso3;
  // An EMPTY page is a brick of only zeros (kernel/page_entry.glsl.h). zero_visible = 1 when the
  // transfer function may show raw value 0 (its normalized value zero_value): such a page is then
  // sampled as the constant zero_value instead of being skipped, so an image never depends on
  // which all-zero bricks exist. Set for "dvr" channels only.
  uint zero_visible;
  float zero_value;
  // Error-bounded LOD (kernel/error_lod.glsl.h): a coarser level's brick may stand in for the
  // LOD's target where its page entry's error code is at least this; 0 = off.
  uint lod_error_code;
};

// One brick-hierarchy level.
struct ResoctLevelInfo {
  uint bricks_x;  // bricks per axis
  uint bricks_y;
  uint bricks_z;
  uint factor_log2_x;  // level voxel = level-0 voxel >> factor_log2
  uint factor_log2_y;
  uint factor_log2_z;
  uint extent_x;  // voxels per axis at this level
  uint extent_y;
  uint extent_z;
  float size_log2;  // log2 of the largest voxel dimension in box units (LOD choice)
  // The residency-octree depth whose nodes are this level's bricks (the same level-0 boxes), the
  // standard-octree mode's culling node; RESOCT_NONE_U (0xFFFFFFFF) when no depth matches.
  uint node_depth;
  // The deepest depth (at least the frame's start_depth) whose nodes span two voxels per axis of
  // this level, one trilinear sample's extent: residency-mode rays sampling this level descend
  // no deeper (host-computed, render/traversal_depths.hpp level_depth_cap).
  uint depth_cap;
};

// One octree depth (see OctreeLayout): node (cx, cy, cz) covers voxels
// [c * node_extent, (c + 1) * node_extent) per axis, clamped to the volume. Children of a node
// are contiguous; local index of a child = (parent_local << child_shift) | child bits, the child
// bits being the low coordinate bit of each split axis, z then y then x with x least significant.
struct ResoctDepthInfo {
  uint count_x;  // nodes per axis
  uint count_y;
  uint count_z;
  uint split_x;  // 1 when this depth halves the axis relative to the previous depth
  uint split_y;
  uint split_z;
  uint child_shift;    // log2 of children per parent (number of split axes)
  uint first_node;     // flat index of the depth's first node
  uint node_extent_x;  // voxels per node per axis (before clamping)
  uint node_extent_y;
  uint node_extent_z;
  uint count_log2_x;  // log2 of count_x .. count_z (counts are powers of two)
  uint count_log2_y;
  uint count_log2_z;
  uint axis_bits_x;  // the bits of a local index that hold the x (y, z) coordinate: a step to
  uint axis_bits_y;  //   the neighbour along an axis is an add within them
  uint axis_bits_z;  //   (resoct_node_neighbor_local)
  // min over the axes of node_extent / voxels_per_box: the nodes' shortest side in box units, to
  // which a ray compares its step (host-computed, render/traversal_depths.hpp).
  float shortest_side;
};

// What one ray reports besides its colour (summed per frame by the backend).
struct ResoctRayStats {
  uint samples;         // samples composited (any channel)
  uint nodes;           // octree nodes (or standard-octree levels) visited
  uint brick_accesses;  // cache-slot reads (per sample and channel)
  uint iterations;      // march iterations
  uint cap_hits;        // 1 when max_iterations stopped the ray
  uint requests;        // request inserts attempted
  float skipped;        // box-space distance skipped as empty
  float marched;        // box-space distance marched inside the volume
  uint gradient_evals;  // gradients computed (shading, isosurface normals)
  uint shadow_rays;     // shadow rays cast
};

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_FRAME_GLSL_H
