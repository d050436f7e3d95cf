#pragma once
/// \file
/// The jitter of one frame: a sub-pixel offset of every pixel's ray and a shift of the samples
/// along each ray, so that averaging frames of an unchanged view (FrameAccumulator) converges to
/// the image of many rays per pixel and a continuous integral along each ray
/// (docs/rendering.md "Jittered accumulation").

#include <cstdint>

namespace resoct {

/// All zero (the default) renders exactly the frame without jitter, bit for bit.
struct FrameJitter {
  float pixel_x = 0.0f;  ///< pixels, to the right, in [-0.5, 0.5)
  float pixel_y = 0.0f;  ///< pixels, down (the direction of rows), in [-0.5, 0.5)
  float sample = 0.0f;   ///< fraction of the sampling step along each ray, in [-0.5, 0.5)

  bool none() const noexcept { return pixel_x == 0.0f && pixel_y == 0.0f && sample == 0.0f; }
  /// Throws Error(invalid_argument) naming "jitter.pixel_x" / "jitter.pixel_y" /
  /// "jitter.sample" when the value is not finite or outside [-0.5, 0.5).
  void validate() const;
  friend bool operator==(const FrameJitter&, const FrameJitter&) = default;
};

/// The radical inverse of `index` in `base` (>= 2): the Halton sequence, in [0, 1).
double halton(std::uint32_t index, std::uint32_t base) noexcept;

/// Frame `index` of a low-discrepancy jitter sequence: index 0 is no jitter (so the first frame
/// of an accumulation is the plain frame), index i >= 1 is Halton(i) - 1/2 in bases 2 and 3 for
/// the sub-pixel offset and base 5 for the sample shift.
FrameJitter halton_jitter(std::uint32_t index) noexcept;

}  // namespace resoct
