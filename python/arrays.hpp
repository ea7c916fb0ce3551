#pragma once
// What every binding file of the Python module shares (python/*.cpp): numpy arrays in and out,
// JSON values as Python objects, and the binding functions each file registers.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/primal/mesh.hpp>

namespace geode::python {

namespace py = pybind11;
using primal::Index;
using primal::Point;

// N x 3 (or N x 2, z = 0) numbers as points; InvalidInput naming `what` for another shape, and
// with `finite` the point (0-based) for a coordinate not finite (conform's model check names it
// by its 1-based id instead, as the command does).
std::vector<Point> to_points(const py::handle& array, const std::string& what, bool finite = true);
// M x K node numbers (any integer dtype) as cells, K = 4, 5, 6 or 8 (tets or quads, pyramids,
// wedges, hexes); InvalidInput naming `what` for another shape or a number outside the 32-bit
// index range (that cell as `cell(i)` names it, where given; else "what: cell i"). Node ranges
// are checked by the library functions.
template <int K>
std::vector<std::array<Index, K>> to_cells(
    const py::handle& array, const std::string& what,
    const std::function<std::string(std::size_t)>& cell = {});
// The number of columns of a 2D cell array (4 or 8 picks quads or hexes); InvalidInput otherwise.
int cell_width(const py::handle& array, const std::string& what);

// Arrays that own their data: the vector is moved to the heap and freed with the array (cells:
// K as for to_cells).
py::array points_array(std::vector<Point>&& points);
template <int K>
py::array cells_array(std::vector<std::array<Index, K>>&& cells);
py::array index_array(std::vector<Index>&& values);
py::array double_array(std::vector<double>&& values);

// JSON values as Python objects (dict, list, str, int, float, bool, None) and back; numpy
// scalars and arrays are accepted on the way in.
py::object to_python(const nlohmann::json& j);
nlohmann::json to_json(const py::handle& object, const std::string& what);

// Registered by python/module.cpp, the exceptions of the module: geode.Error and its kinds.
void bind_templates(py::module_& m);  // python/templates.cpp: template, arrange, study
void bind_mesh(py::module_& m);       // python/mesh.cpp: check, quality, dual, smooth, isomorphism
void bind_conform(py::module_& m);    // python/conform.cpp: conform, demo models

}  // namespace geode::python
