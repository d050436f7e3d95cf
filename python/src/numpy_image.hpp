#pragma once
// Images as numpy arrays shaped (height, width, 4): float32 straight-alpha RGBA or uint8 RGBA,
// row 0 at the top, which is what matplotlib's imshow and napari take as they are.

#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/numpy.h>

#include "bindings.hpp"
#include "resoct/backend/image.hpp"

namespace resoct::python {

/// A view of `image`'s pixels kept alive by `owner` (the Python object holding the image).
py::array float_view(const Image& image, py::handle owner);
/// A view of 8-bit RGBA bytes kept alive by `owner`.
py::array rgba8_view(const std::vector<std::uint8_t>& rgba, std::uint32_t width,
                     std::uint32_t height, py::handle owner);
/// "int64", "float64", ...: for errors about an array's element type.
std::string dtype_name(const py::dtype& dtype);
/// An array owning `rgba` (moved into it).
py::array rgba8_array(std::vector<std::uint8_t> rgba, std::uint32_t width, std::uint32_t height);

}  // namespace resoct::python
