#pragma once
/// \file
/// Averaging jittered frames of an unchanged view into a noise-free still (docs/rendering.md
/// "Jittered accumulation"): a viewer asks for the jitter of the next frame, renders with it
/// (Renderer::render_frame(scene, report, jitter)) and adds the frame. The average restarts when
/// the scene changes or the resident bricks do.

#include <cstdint>
#include <optional>
#include <vector>

#include "resoct/backend/image.hpp"
#include "resoct/render/frame_jitter.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct {

class FrameAccumulator {
 public:
  /// Averages at most `max_frames` frames (>= 1; Error(invalid_argument) naming "max_frames").
  explicit FrameAccumulator(std::uint32_t max_frames = 16);

  /// The jitter to render the next frame of `scene` with. A scene other than the one of the
  /// frames summed so far (any field: camera, viewport, channels, timepoint, ...) restarts the
  /// average and the jitter sequence, whose first frame has no jitter (halton_jitter).
  FrameJitter next(const Scene& scene);
  /// Adds the frame rendered with the jitter next() returned; its float pixels are
  /// `report.image` (output rgba32f, both, or device on the CPU backend). A frame that uploaded
  /// bricks (the resident set changed, so the older frames show other data) starts the average
  /// anew with itself. Throws Error(invalid_argument) naming "report" when it carries no float
  /// image or one of another size than the scene's viewport, and naming "scene" when next() was
  /// not called since the last add().
  void add(const FrameReport& report);
  /// The same for a frame whose float pixels the caller holds (e.g. read back from a device).
  void add(const Image& frame, bool resident_set_changed);
  /// Drops the average (the next frame starts a new one; the jitter sequence goes on).
  void restart() noexcept;

  /// True when the average holds frames of `scene` (the next frame of it continues it).
  bool accumulating(const Scene& scene) const { return frames_ > 0 && scene_ && *scene_ == scene; }
  /// Frames in the average.
  std::uint32_t frames() const noexcept { return frames_; }
  std::uint32_t max_frames() const noexcept { return max_frames_; }
  /// True once max_frames() frames are averaged: a viewer stops rendering the still view.
  bool done() const noexcept { return frames_ >= max_frames_; }
  /// The average of the frames added since the last restart (empty before the first). One
  /// frame's average is that frame, bit for bit.
  const Image& image() const noexcept { return average_; }

 private:
  std::uint32_t max_frames_;
  std::optional<Scene> scene_;  // the scene of the summed frames
  bool pending_ = false;        // next() was called, add() not yet
  std::uint32_t sequence_ = 0;  // jitter index of the next frame
  std::uint32_t frames_ = 0;
  std::vector<double> sum_;  // RGBA per pixel
  Image average_;
};

/// Renders `scene` until converged (at most `max_converge_frames`, Renderer::
/// render_until_converged), then averages `frames` jittered frames of it (the first one
/// unjittered) and returns the average. Jittered frames can need bricks the plain frame did not
/// (a shifted sample crosses into another brick): the average then restarts when they arrive,
/// with at most 4 * `frames` + `max_converge_frames` frames in all. The renderer's output must
/// carry float pixels on the host (Error(invalid_argument) naming "output" otherwise); `frames`
/// >= 1 ("frames").
Image render_accumulated(Renderer& renderer, const Scene& scene, std::uint32_t frames,
                         std::uint32_t max_converge_frames = 1000);

}  // namespace resoct
