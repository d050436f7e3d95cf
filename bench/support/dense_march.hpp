#pragma once
// The "ideal dense in-core march" (issue 13): the limit resoct's CPU backend is measured against.
//
// One channel's level-0 voxels in one flat array, and the same per-ray definition as the kernel
// (docs/rendering.md): the same camera rays (float, through pixel centres), the same step
// (Eq. 8.2-8.3 at level-0 voxels, rounded down to its step level), segments [t, t + Δ) with
// Δ = min(dt, t_exit − t) sampled at their midpoints, trilinear interpolation with clamp-to-edge,
// the 1024-entry TF LUT with linear interpolation between entries, full steps from the level's
// opacity-corrected, premultiplied LUT and the last, shorter one corrected per sample
// (1 − (1 − α)^(Δ/Δ₀), kernel/step_lut.glsl.h), front-to-back
// compositing and early termination at the scene's ert_opacity; 16×16 tiles over OpenMP with
// dynamic scheduling like the CPU backend. No bricks, no octree, no page table, no empty-space
// skipping, no level of detail: every segment of every ray inside the volume is sampled at level 0
// until the ray saturates.
//
// Tight scalar code: per-frame and per-ray constants are hoisted (camera basis, step, Δ/Δ₀ of a
// full step, strides, the position of the ray origin in array coordinates), whole steps and the
// shorter last segment run in separate loops, the array carries a one-voxel clamp-to-edge border
// so that the trilinear footprint needs no clamping or edge cases, the voxel type is a template
// parameter (no per-sample dispatch or virtual call), and a sample whose interpolated TF alpha is
// 0 stops before colour, logarithm and exponential. The arithmetic follows the kernel's operation
// order (camera ray, step, trilinear weights, LUT, opacity series, compositing); only sample
// positions round differently (origin + t·d in array coordinates instead of the kernel's
// cell + fraction split, a few 1e-5 voxel), so where the backend samples the same level the
// images agree to float rounding, except that a ray whose opacity lands within rounding of
// ert_opacity may stop one sample earlier in one of them. bench_limit reports the difference.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "resoct/sources/brick_source.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/scene/scene.hpp"
#include "resoct/scene/step_lut.hpp"

namespace resoct::bench {

/// Level-0 voxels of one channel in memory, in the volume's own voxel type, x fastest, then y,
/// then z, with a border of one voxel on every side that repeats the nearest edge voxel
/// (clamp to edge): voxel (x, y, z) of the volume is element
/// ((z + 1) · (ey + 2) + (y + 1)) · (ex + 2) + (x + 1).
struct DenseVolume {
  VolumeDesc volume;  ///< extent, type, spacing and value ranges of the source
  std::uint32_t channel = 0;
  glm::uvec3 padded{0};           ///< extent + 2
  std::vector<std::byte> voxels;  ///< padded.x · padded.y · padded.z voxels of volume.type

  /// Reads the level-0 bricks of `channel` from any source (their cores, without the halo) and
  /// adds the border. Throws Error(invalid_argument) naming "channel" when it does not exist.
  static DenseVolume read(const BrickSource& source, std::uint32_t channel);

  /// The level-0 voxels without the border, x fastest (for dumps and comparisons).
  std::vector<std::byte> core() const;
};

/// Counters of one frame.
struct DenseStats {
  std::uint64_t rays = 0;
  std::uint64_t samples = 0;          ///< segments evaluated (trilinear + TF lookup)
  std::uint64_t visible_samples = 0;  ///< of those, samples with TF alpha > 0 (composited)
};

/// One composited sample of a ray: its midpoint and its length in reference steps; a negative
/// `ratio` marks a full step of the ray's step level, whose colour comes from that level's
/// opacity-corrected LUT.
struct VisibleSample {
  float tm = 0.0f;
  float ratio = 0.0f;
};

/// The samples of a frame that a renderer with perfect culling at no cost would compute: per ray,
/// those whose transfer-function alpha is above zero, up to early termination. Ray p (pixel
/// y · width + x) owns samples[offsets[p], offsets[p + 1]).
struct VisibleSamples {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint64_t> offsets;
  std::vector<VisibleSample> samples;
};

/// A scene prepared for one dense volume: frame and per-channel constants computed once.
/// Immutable after construction; render() may run concurrently with itself on other images.
class DenseMarch {
 public:
  /// The scene must show exactly the channel of `volume`, in "dvr" mode, with finest level 0,
  /// without effects, slices, lens or pre-integration; throws Error(invalid_argument) naming
  /// "scene" otherwise, and naming "volume" for an axis above 65536 voxels (float positions).
  /// `volume` must outlive the march. The caller makes sure the compared renderer samples level 0
  /// as well (levels [0, 0], or a view whose LOD picks level 0 everywhere).
  DenseMarch(const DenseVolume& volume, const Scene& scene);

  /// Renders the scene into `image` (resized to the viewport; straight alpha like
  /// FrameResult::image) on `threads` OpenMP threads (<= 0: all).
  DenseStats render(Image& image, int threads) const;

  /// The visible samples of every ray of render() (an untimed pass of the dense march that keeps
  /// them).
  VisibleSamples record_visible(int threads) const;

  /// The oracle-culling bound: renders only `visible` (record_visible of this march): the per-ray
  /// set-up, then exactly the samples that add colour, with the dense march's arithmetic, so the
  /// image equals render()'s bit for bit (a transparent sample adds nothing), while no sample,
  /// node or brick is spent on finding them. No exact renderer with this per-ray definition can
  /// sample less. DenseStats::samples counts the samples evaluated (= visible_samples). Throws
  /// Error(invalid_argument) naming "visible" when it was recorded for another viewport.
  DenseStats render_visible(Image& image, const VisibleSamples& visible, int threads) const;

  /// Constants of one frame, as the kernel's frame record holds them (floats).
  struct Frame {
    std::uint32_t width = 0, height = 0;
    float half_height = 0.0f;
    bool perspective = true;
    glm::vec3 forward{0.0f}, right{0.0f}, up{0.0f};
    glm::ivec3 eye_cell{0};
    glm::vec3 eye_frac{0.0f};
    glm::vec3 voxels_per_box{0.0f};
    glm::vec3 finest_voxel{0.0f};
    float step_scale = 1.0f, min_step = 0.0f, ref_step = 0.0f, ert_opacity = 0.99f;
    glm::vec4 background{0.0f};
    float range_lo = 0.0f, inv_range_width = 1.0f;
    glm::ivec3 extent{0};
  };
  const Frame& frame() const noexcept { return frame_; }

 private:
  const DenseVolume& volume_;
  Frame frame_;
  std::vector<glm::vec4> lut_;
  StepLevels levels_;                  // the frame's step levels (kernel/step_lut.glsl.h)
  std::vector<glm::vec4> level_luts_;  // their corrected, premultiplied LUTs, level by level
};

}  // namespace resoct::bench
