// Open a source, make a backend, render one frame to a PNG.
#include <cstdio>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/resoct.hpp"

int main(int argc, char** argv) {
  const char* spec = argc > 1 ? argv[1] : "procedural:tubes:128x128x128";
  const char* png = argc > 2 ? argv[2] : "frame.png";

  resoct::Renderer renderer(resoct::open_source(spec), resoct::cpu::make_backend());
  const resoct::Scene scene = resoct::overview_scene(renderer.hierarchy().volume());

  // The first frames show coarse levels while bricks load; render until nothing is missing.
  const resoct::ConvergeReport result = renderer.render_until_converged(scene);
  resoct::write_png(result.last.image, png);

  const resoct::BackendStats& s = result.last.stats.backend;
  std::printf("%s: %u frames, %s, %.1f samples per ray\n", png, result.frames,
              result.converged ? "converged" : "not converged", resoct::per_ray(s.samples, s));
  return result.converged ? 0 : 1;
}
