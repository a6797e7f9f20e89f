// cosmic._native: the extension module behind the Python package `cosmic` (lib/python/cosmic has
// the Pythonic layer, the exceptions and the type stubs).
#include "binding.hpp"

namespace cosmic::python {

namespace {
py::object& error_factory() {
  static py::object* factory = nullptr;  // cosmic._errors.error_for; lives as long as the process
  if (!factory) factory = new py::object(py::module_::import("cosmic._errors").attr("error_for"));
  return *factory;
}
}  // namespace

void raise_error(int code, const std::string& message) {
  py::object error = error_factory()(code, message);
  PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
  throw py::error_already_set();
}

void raise_closed(const std::string& what) {
  py::object error =
      py::module_::import("cosmic._errors").attr("ClosedError")(static_cast<int>(COSMIC_E_INVALID), what);
  PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
  throw py::error_already_set();
}

}  // namespace cosmic::python

PYBIND11_MODULE(_native, m) {
  namespace py = pybind11;
  m.doc() = "libcosmic-client for Python: the native part of the package `cosmic` (import cosmic instead).";
  m.attr("OK") = py::int_(static_cast<int>(COSMIC_OK));
  m.attr("E_INVALID") = py::int_(static_cast<int>(COSMIC_E_INVALID));
  m.attr("E_TRANSPORT") = py::int_(static_cast<int>(COSMIC_E_TRANSPORT));
  m.attr("E_AGAIN") = py::int_(static_cast<int>(COSMIC_E_AGAIN));
  m.attr("E_TOO_LARGE") = py::int_(static_cast<int>(COSMIC_E_TOO_LARGE));
  m.attr("E_UNBOUND") = py::int_(static_cast<int>(COSMIC_E_UNBOUND));
  m.attr("E_UNAVAILABLE") = py::int_(static_cast<int>(COSMIC_E_UNAVAILABLE));
  m.attr("E_TIMEOUT") = py::int_(static_cast<int>(COSMIC_E_TIMEOUT));
  m.attr("PUBLISH") = py::int_(static_cast<int>(COSMIC_PUBLISH));
  m.attr("SUBSCRIBE") = py::int_(static_cast<int>(COSMIC_SUBSCRIBE));
  cosmic::python::bind_client(m);
  cosmic::python::bind_channel(m);
  cosmic::python::bind_model(m);
}
