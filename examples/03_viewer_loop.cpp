// A viewer's loop: orbit the camera, change a transfer function half-way round, and stop
// rendering each view once it has converged. The one FrameReport is reused, so frames allocate
// no image memory.
#include <cstdio>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/resoct.hpp"

int main() {
  resoct::ViewerOptions options;
  options.output = resoct::FrameOutput::rgba8;  // what a texture upload takes
  resoct::Renderer renderer(resoct::open_source("procedural:cells:128x128x32"),
                            resoct::cpu::make_backend(), options);
  resoct::Scene scene = resoct::overview_scene(renderer.hierarchy().volume(), {256, 256});
  resoct::FrameReport frame;
  for (int view = 0; view < 6; ++view) {
    scene.camera = resoct::orbit(scene.camera, 30.0);
    if (view == 3) {  // channel 1 turns red and denser
      scene.channels[1].tf = resoct::TransferFunction(
          {{0.0, {1.0, 0.1, 0.1, 0.0}}, {0.2, {1.0, 0.1, 0.1, 0.0}}, {1.0, {1.0, 0.2, 0.1, 0.9}}});
    }
    std::uint32_t frames = 0;
    do {
      renderer.render_frame(scene, frame);  // a viewer shows frame.rgba8 and polls input here
      ++frames;
    } while (!frame.converged && frames < 1000);
    std::printf("view %d: %u frames to converge, %llu bricks resident\n", view, frames,
                static_cast<unsigned long long>(frame.stats.resident_bricks));
    if (!frame.converged) return 1;
  }
  return 0;
}
