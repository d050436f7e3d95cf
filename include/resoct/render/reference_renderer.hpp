#pragma once
/// \file
/// The dense reference renderer: level 0 only, double precision, tiny steps, no culling, no
/// bricks. It renders exactly the definition in docs/rendering.md with the most direct code
/// possible, so that the library's renderers can be compared against it: the tests' oracle, the
/// accuracy benchmark's reference and `resoct-render --report-accuracy`'s (docs/renderer.md).
//
// Choices that make it an oracle rather than a copy of the kernel:
// - transfer functions are evaluated exactly (TransferFunction::evaluate in double), not through
//   the LUT, so LUT quantisation shows up as (small, bounded) error of the renderer under test;
// - samples sit at the midpoints of equal segments of length `step` between entry and exit, with
//   a shorter last segment, each with its own opacity correction, so a constant medium gives the
//   closed form 1 − exp(−σL) for any step;
// - ray/box intersection is written here independently of kernel/ray.glsl.h (same half-open
//   convention);
// - effects (docs/rendering.md "Effects"): "shading" lights DVR samples with the level-0
//   gradient; iso channels find crossings between consecutive reference samples and bisect the
//   trilinear field in double (60 halvings), the surface lit with the gradient at the hit; MIP /
//   AIP project the clamped normalized value and are composited behind. Shadows are not
//   modelled (tests check them against geometry).

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "resoct/scene/camera.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/scene/scene.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct::reference {

/// Raw value of `channel` at level-0 voxel `voxel` (always inside the extent).
using VoxelFunction = std::function<double(std::uint32_t channel, const glm::i64vec3& voxel)>;

/// A VoxelFunction over dense level-0 buffers, one per channel, x fastest then y then z. Throws
/// Error(size_mismatch) when a buffer does not hold extent.x * extent.y * extent.z values.
VoxelFunction dense_voxels(const glm::u64vec3& extent, std::vector<std::vector<double>> channels);

struct ReferenceOptions {
  /// Step length in reference steps Δ₀ (Δ₀ = smallest level-0 voxel dimension in box units).
  double step = 1.0 / 16.0;
  /// Apply the scene's early ray termination (the renderers under test do).
  bool early_termination = true;
  /// Deliberate defects, for tests that show a tolerance can catch a bug: every DVR sample is
  /// taken this far (level-0 voxels) from where it belongs, and its transfer-function opacity is
  /// multiplied by opacity_scale (capped at 1). Both are off by default.
  glm::dvec3 sample_offset{0.0};
  double opacity_scale = 1.0;
  /// render_reference's threads (rows interleaved; 0 = one per core). Every pixel is computed
  /// alike whatever the count, so the image does not depend on it.
  std::uint32_t threads = 1;
};

/// Trilinear interpolation at a continuous level-0 voxel position (voxel i has its centre at
/// i + 0.5), clamped to the edge voxels outside the centres.
double sample_trilinear(const VoxelFunction& voxels, std::uint32_t channel,
                        const glm::u64vec3& extent, const glm::dvec3& pos);

/// Smallest level-0 voxel dimension in box units: the reference step Δ₀ of transfer-function
/// alpha.
double reference_step(const VolumeDesc& volume);

/// Half-open slab test in double: (t_enter, t_exit) of the ray with [lo, hi); hit iff enter <
/// exit.
glm::dvec2 reference_ray_box(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi);

/// Box-space gradient of channel `c`'s normalized level-0 field at `pos` (level-0 voxels):
/// central (or, with `forward`, forward) differences at ± one voxel of the clamp-to-edge
/// trilinear field (docs/rendering.md "Effects").
glm::dvec3 reference_gradient(const VolumeDesc& volume, const VoxelFunction& voxels,
                              std::uint32_t channel, const glm::dvec3& pos, bool forward = false);

/// Blinn-Phong of docs/rendering.md "Effects" in double, without shadows: straight colour `rgb`
/// lit with the normal from `gradient`, light from `scene.light` at box position `pos_box`.
glm::dvec3 reference_shade(const Scene& scene, const glm::dvec3& rgb, const glm::dvec3& gradient,
                           const glm::dvec3& pos_box, const glm::dvec3& view_dir);

/// Premultiplied RGBA accumulated along one ray (box units, t >= 0), before the background.
glm::dvec4 reference_ray(const Scene& scene, const VolumeDesc& volume, const VoxelFunction& voxels,
                         const Ray& ray, const ReferenceOptions& options = {});

/// The whole image: every pixel's ray over the scene's background, straight alpha.
Image render_reference(const Scene& scene, const VolumeDesc& volume, const VoxelFunction& voxels,
                       const ReferenceOptions& options = {});

}  // namespace resoct::reference
