// geode._geode: the library's entry points for Python (the package python/geode wraps them).
// Errors become geode.Error subclasses carrying the library's message and the exit code the
// command line gives the same failure: InputError (2, also a ValueError), TopologyError (3),
// InvalidResultError (4, raised by geode.conform for a result that fails verification).
#include <Python.h>

#include "python/arrays.hpp"

#ifndef GEODE_VERSION
#define GEODE_VERSION "unknown"
#endif

namespace geode::python {
namespace {

py::object new_exception(py::module_& m, const char* name, py::handle bases, const char* kind,
                         int exit_code, const char* doc) {
  const std::string full = std::string("geode.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw py::error_already_set();
  py::object t = py::reinterpret_steal<py::object>(type);
  t.attr("kind") = kind;
  t.attr("exit_code") = exit_code;
  m.attr(name) = t;
  return t;
}

}  // namespace
}  // namespace geode::python

PYBIND11_MODULE(_geode, m) {
  using namespace geode::python;
  m.doc() = "geode: all-hex meshing through the dual sheet arrangement (C++ core)";
  m.attr("__version__") = GEODE_VERSION;
  py::object error = new_exception(m, "Error", PyExc_Exception, "error", 1,
                                   "A geode failure; see kind and exit_code.");
  // Kept for the life of the process (the translator outlives any module object).
  static PyObject* input_error =
      new_exception(m, "InputError", py::make_tuple(error, py::handle(PyExc_ValueError)), "input",
                    2, "Bad input: the message names the argument, element or node.")
          .release()
          .ptr();
  static PyObject* topology_error =
      new_exception(m, "TopologyError", py::make_tuple(error), "topology", 3,
                    "Well-formed input that is topologically unusable (the diagnosis).")
          .release()
          .ptr();
  new_exception(m, "InvalidResultError", py::make_tuple(error), "invalid result", 4,
                "A computed result that fails verification.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const geode::InvalidInput& e) {
      PyErr_SetString(input_error, e.what());
    } catch (const geode::TopologyError& e) {
      PyErr_SetString(topology_error, e.what());
    }
  });
  bind_templates(m);
  bind_mesh(m);
  bind_conform(m);
}
