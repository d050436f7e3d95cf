// resoct.Scene: what to render, built from a dict or JSON in the scene format (docs/scene.md),
// loaded from a file, or made for a source by overview_scene(); a few camera properties for
// viewer loops.
#include <optional>
#include <string>

#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "resoct/sources/brick_source.hpp"
#include "resoct/scene/camera.hpp"
#include "resoct/base/error.hpp"
#include "resoct/scene/overview_scene.hpp"

namespace resoct::python {

namespace {

// numpy values (arrays, float32 scalars) in a scene dict become plain lists and numbers; any
// other object json cannot write is a TypeError from json itself.
py::object to_plain(py::handle value) {
  if (py::hasattr(value, "tolist")) return value.attr("tolist")();
  throw py::type_error("scene: cannot convert " + py::repr(value).cast<std::string>() + " to JSON");
}

Scene from_dict(const py::dict& d) {
  const py::module_ json = py::module_::import("json");
  const std::string text =
      json.attr("dumps")(d, py::arg("default") = py::cpp_function(&to_plain)).cast<std::string>();
  return parse_scene(text, "scene");
}

py::dict to_dict(const Scene& s) {
  return py::module_::import("json").attr("loads")(scene_to_json(s));
}

py::tuple tuple3(const glm::dvec3& v) {
  return py::make_tuple(v.x, v.y, v.z);
}

glm::dvec3 vec3(const std::tuple<double, double, double>& t) {
  return {std::get<0>(t), std::get<1>(t), std::get<2>(t)};
}

Viewport viewport_of(std::uint32_t width, std::uint32_t height) {
  return Viewport{width, height};
}

}  // namespace

const Scene& scene_arg(py::handle scene, Scene& storage) {
  if (py::isinstance<py::dict>(scene)) {
    storage = from_dict(scene.cast<py::dict>());
    return storage;
  }
  if (!py::isinstance<Scene>(scene)) {
    throw invalid_parameter("scene", "must be a resoct.Scene or a dict, not " +
                                         py::str(scene.get_type()).cast<std::string>());
  }
  return scene.cast<const Scene&>();
}

void bind_scenes(py::module_& m) {
  py::class_<Scene>(m, "Scene",
                    "What to render: camera, viewport, channels with transfer functions, "
                    "sampling and effects (the scene JSON format, docs/scene.md).")
      .def(py::init(&from_dict), py::arg("scene"), "The same as Scene.from_dict.")
      .def_static("from_dict", &from_dict, py::arg("scene"),
                  "Parses a dict in the scene JSON format; errors name the JSON path.")
      .def_static(
          "from_json", [](const std::string& text) { return parse_scene(text, "scene"); },
          py::arg("text"))
      .def_static("load", &load_scene, py::arg("path"))
      .def("to_dict", &to_dict)
      .def("to_json", &scene_to_json)
      .def(
          "save", [](const Scene& s, const std::string& path) { save_scene(s, path); },
          py::arg("path"))
      .def_property(
          "width", [](const Scene& s) { return s.viewport.width; },
          [](Scene& s, std::uint32_t w) { s.viewport = viewport_of(w, s.viewport.height); })
      .def_property(
          "height", [](const Scene& s) { return s.viewport.height; },
          [](Scene& s, std::uint32_t h) { s.viewport = viewport_of(s.viewport.width, h); })
      .def_property(
          "eye", [](const Scene& s) { return tuple3(s.camera.eye); },
          [](Scene& s, const std::tuple<double, double, double>& v) { s.camera.eye = vec3(v); })
      .def_property(
          "target", [](const Scene& s) { return tuple3(s.camera.target); },
          [](Scene& s, const std::tuple<double, double, double>& v) { s.camera.target = vec3(v); })
      .def_property(
          "up", [](const Scene& s) { return tuple3(s.camera.up); },
          [](Scene& s, const std::tuple<double, double, double>& v) { s.camera.up = vec3(v); })
      .def_property(
          "timepoint", [](const Scene& s) { return s.timepoint; },
          [](Scene& s, std::optional<std::uint32_t> t) { s.timepoint = t; })
      .def(
          "orbit", [](Scene& s, double degrees) { s.camera = orbit(s.camera, degrees); },
          py::arg("degrees"),
          "Turns the camera's eye about the axis through the target along `up`, in place.")
      .def(py::self == py::self)
      .def("__repr__", [](const Scene& s) {
        return "<resoct.Scene " + std::to_string(s.viewport.width) + "x" +
               std::to_string(s.viewport.height) + ", " + std::to_string(s.channels.size()) +
               " channels>";
      });

  m.def(
      "overview_scene",
      [](const BrickSource& source, std::uint32_t width, std::uint32_t height) {
        return overview_scene(source.hierarchy().volume(), viewport_of(width, height));
      },
      py::arg("source"), py::kw_only(), py::arg("width") = 512u, py::arg("height") = 512u,
      "The whole volume in view with up to four channels visible, each a colour ramp.");
}

}  // namespace resoct::python
