// The Python module `lucent` (issue 38): what its parts share. NumPy arrays in and out, lucent's
// units in the names (mm, mm^-1), lucent::Error raised as lucent.Error with the same one line.
#pragma once

#include <array>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <nlohmann/json.hpp>

namespace lucent::python {

namespace py = pybind11;

/// A JSON document as Python objects (dict, list, float...), through Python's json module.
py::object to_python(const nlohmann::json& doc);
/// Python objects (dict, list, ...) as a JSON document.
nlohmann::json from_python(const py::handle& object);

/// A double array of any shape, C-contiguous (copied when it is not).
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

void bind_materials(py::module_& m);
void bind_profiles(py::module_& m);
void bind_fit(py::module_& m);
void bind_simulate(py::module_& m);
void bind_render(py::module_& m);

}  // namespace lucent::python
