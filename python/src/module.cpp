// The Python module's entry point: the exception and the parts (bindings.h).
#include "bindings.h"
#include "lucent/core/error.h"

namespace lucent::python {

py::object to_python(const nlohmann::json& doc) {
  return py::module_::import("json").attr("loads")(doc.dump());
}

nlohmann::json from_python(const py::handle& object) {
  const std::string text = py::str(py::module_::import("json").attr("dumps")(object));
  return nlohmann::json::parse(text);
}

}  // namespace lucent::python

PYBIND11_MODULE(_lucent, m) {
  namespace lp = lucent::python;
  m.doc() = "lucent: measure translucent materials and model them (units: mm, mm^-1)";
  // Bad input: the CLI's one line, as an exception a caller can catch (a ValueError).
  static lp::py::exception<lucent::Error> error(m, "Error", PyExc_ValueError);
  lp::py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const lucent::Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });
  lp::bind_materials(m);
  lp::bind_profiles(m);
  lp::bind_fit(m);
  lp::bind_simulate(m);
  lp::bind_render(m);
}
