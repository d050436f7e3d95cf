// The `resoct` Python module (docs/python.md): open sources, set up renderers, render frames and
// read them as numpy arrays.
#include "bindings.hpp"
#include "resoct/version.hpp"

PYBIND11_MODULE(resoct, m) {
  using namespace resoct::python;
  m.doc() = "Out-of-core multi-resolution multi-channel volume rendering (resoct)";
  bind_errors(m);
  bind_sources(m);
  bind_scenes(m);
  bind_images(m);
  bind_renderer(m);
  // The library actually loaded, which is what a bug report needs.
  m.attr("__version__") = resoct::library_version();
  m.attr("kernel_layout_version") = resoct::library_kernel_layout_version();
}
