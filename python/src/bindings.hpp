#pragma once
// The parts of the `resoct` Python module, each bound by its own file; module.cpp calls them in
// dependency order (errors first, so that every later binding's errors translate).

#include <pybind11/pybind11.h>

#include "resoct/scene/scene.hpp"

namespace resoct::python {

namespace py = pybind11;

void bind_errors(py::module_& m);
void bind_sources(py::module_& m);
void bind_scenes(py::module_& m);
void bind_images(py::module_& m);
void bind_renderer(py::module_& m);

/// A Scene, or a dict in the scene JSON format (docs/scene.md) parsed into `storage`: what every
/// function taking a scene accepts. Errors name the offending JSON path ("scene: camera.eye: ...").
const Scene& scene_arg(py::handle scene, Scene& storage);

}  // namespace resoct::python
