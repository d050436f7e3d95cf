#include "numpy_image.hpp"

#include <utility>

namespace resoct::python {

namespace {

template <typename T>
py::array rgba_view(const T* data, std::uint32_t width, std::uint32_t height, py::handle owner) {
  const auto px = py::ssize_t(4 * sizeof(T));
  return py::array_t<T>({py::ssize_t(height), py::ssize_t(width), py::ssize_t(4)},
                        {px * py::ssize_t(width), px, py::ssize_t(sizeof(T))}, data, owner);
}

}  // namespace

py::array float_view(const Image& image, py::handle owner) {
  return rgba_view(&image.pixels().data()->x, image.width(), image.height(), owner);
}

py::array rgba8_view(const std::vector<std::uint8_t>& rgba, std::uint32_t width,
                     std::uint32_t height, py::handle owner) {
  return rgba_view(rgba.data(), width, height, owner);
}

std::string dtype_name(const py::dtype& dtype) {
  return py::str(static_cast<py::handle>(dtype)).cast<std::string>();
}

py::array rgba8_array(std::vector<std::uint8_t> rgba, std::uint32_t width, std::uint32_t height) {
  auto* owned = new std::vector<std::uint8_t>(std::move(rgba));
  const py::capsule free_when_done(
      owned, [](void* p) { delete static_cast<std::vector<std::uint8_t>*>(p); });
  return rgba8_view(*owned, width, height, free_when_done);
}

}  // namespace resoct::python
