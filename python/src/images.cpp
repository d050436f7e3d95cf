// PNG files to and from numpy arrays, with the library's reader and atomic writer.
#include <cstring>
#include <string>

#include "bindings.hpp"
#include "numpy_image.hpp"
#include "resoct/base/error.hpp"

namespace resoct::python {

namespace {

// (height, width, 4) of float32 (straight RGBA in [0, 1]) or uint8.
void write(const py::array& input, const std::string& path) {
  if (input.ndim() != 3 || input.shape(2) != 4) {
    throw invalid_parameter("image", "must be shaped (height, width, 4)");
  }
  const auto height = std::uint32_t(input.shape(0));
  const auto width = std::uint32_t(input.shape(1));
  const py::array a = py::array::ensure(input, py::array::c_style);
  if (a.dtype().is(py::dtype::of<std::uint8_t>())) {
    const auto* bytes = static_cast<const std::uint8_t*>(a.data());
    write_png(width, height, std::span(bytes, std::size_t(a.size())), path);
  } else if (a.dtype().is(py::dtype::of<float>())) {
    Image image(width, height);
    std::memcpy(image.pixels().data(), a.data(), std::size_t(a.nbytes()));
    write_png(image, path);
  } else {
    throw invalid_parameter("image",
                            "dtype must be float32 or uint8, not " + dtype_name(a.dtype()));
  }
}

py::array read(const std::string& path) {
  const Image image = read_png(path);
  return rgba8_array(image.to_rgba8(), image.width(), image.height());
}

}  // namespace

void bind_images(py::module_& m) {
  m.def("write_png", &write, py::arg("image"), py::arg("path"),
        "Writes a (height, width, 4) float32 or uint8 RGBA array as an 8-bit PNG, atomically.");
  m.def("read_png", &read, py::arg("path"),
        "Reads a PNG as a (height, width, 4) uint8 RGBA array.");
}

}  // namespace resoct::python
