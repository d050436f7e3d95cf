// resoct::Error becomes resoct.Error (a RuntimeError) carrying the library's message, which names
// the parameter, file or JSON path at fault, and its code ("invalid_argument", "io", ...).
#include "bindings.hpp"
#include "resoct/base/error.hpp"

namespace resoct::python {

void bind_errors(py::module_& m) {
  // Lives as long as the interpreter's module; pybind11 keeps a reference in the module too.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  error.doc() =
      "An error of the resoct library. str(e) is its message, e.code the error class (e.g. "
      "'invalid_argument', 'io', 'corrupt').";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      // Called through a handle: py::exception::operator() would only set the error string.
      py::object instance = py::handle(error.ptr())(e.what());
      instance.attr("code") = std::string(to_string(e.code()));
      PyErr_SetObject(error.ptr(), instance.ptr());
    }
  });
}

}  // namespace resoct::python
