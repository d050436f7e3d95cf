#include "resoct/render/frame_accumulator.hpp"

#include <string>

#include "resoct/base/error.hpp"

namespace resoct {

FrameAccumulator::FrameAccumulator(std::uint32_t max_frames) : max_frames_(max_frames) {
  if (max_frames == 0) throw invalid_parameter("max_frames", "must be >= 1");
}

FrameJitter FrameAccumulator::next(const Scene& scene) {
  if (!scene_ || !(*scene_ == scene)) {
    scene_ = scene;
    sequence_ = 0;
    restart();
  }
  pending_ = true;
  return halton_jitter(sequence_);
}

void FrameAccumulator::restart() noexcept {
  frames_ = 0;
  average_ = Image();
}

void FrameAccumulator::add(const FrameReport& report) {
  add(report.image, report.stats.bricks_uploaded != 0);
}

void FrameAccumulator::add(const Image& frame, bool resident_set_changed) {
  if (!pending_ || !scene_) {
    throw invalid_parameter("scene", "add() without next(): the frame's jitter is unknown");
  }
  const Viewport vp = scene_->viewport;
  if (frame.width() != vp.width || frame.height() != vp.height) {
    throw invalid_parameter(
        "report", "the frame is " + std::to_string(frame.width()) + "x" +
                      std::to_string(frame.height()) + " (no float image?), the scene's viewport " +
                      std::to_string(vp.width) + "x" + std::to_string(vp.height));
  }
  pending_ = false;
  ++sequence_;
  if (resident_set_changed) restart();
  const std::vector<glm::vec4>& px = frame.pixels();
  sum_.resize(px.size() * 4);
  if (frames_ == 0) {
    std::fill(sum_.begin(), sum_.end(), 0.0);
    average_ = Image(vp.width, vp.height);
  }
  ++frames_;
  // Sums in double: thousands of float frames would lose the low bits of each one.
  const double inv = 1.0 / double(frames_);
  std::vector<glm::vec4>& out = average_.pixels();
  for (std::size_t i = 0; i < px.size(); ++i) {
    for (int c = 0; c < 4; ++c) {
      double& s = sum_[i * 4 + std::size_t(c)];
      s += double(px[i][c]);
      out[i][c] = float(s * inv);  // one frame: float(double(x) * 1) == x
    }
  }
}

Image render_accumulated(Renderer& renderer, const Scene& scene, std::uint32_t frames,
                         std::uint32_t max_converge_frames) {
  if (frames == 0) throw invalid_parameter("frames", "must be >= 1");
  const FrameOutput out = renderer.options().output;
  if (out == FrameOutput::rgba8) {
    throw invalid_parameter("output", "accumulation needs the float image (rgba32f or both)");
  }
  ConvergeReport first = renderer.render_until_converged(scene, max_converge_frames);
  if (first.last.image.width() != scene.viewport.width ||
      first.last.image.height() != scene.viewport.height) {
    throw invalid_parameter("output", "accumulation needs the float image on the host");
  }
  FrameAccumulator acc(frames);
  FrameReport report = std::move(first.last);
  const std::uint64_t limit = 4ull * frames + max_converge_frames;
  for (std::uint64_t n = 0; !acc.done() && n < limit; ++n) {
    const FrameJitter j = acc.next(scene);
    renderer.render_frame(scene, report, j);
    acc.add(report);
    // Bricks a jittered frame requested: let them arrive, so that the restart comes early.
    if (!report.converged) renderer.wait_for_loads();
  }
  return acc.image();
}

}  // namespace resoct
