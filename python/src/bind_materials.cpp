// lucent.Material, the library, and the models evaluated over NumPy arrays: radial profiles and
// totals, the BSSRDF over configurations, Fresnel, the albedo inversion.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "bindings.h"
#include "lucent/core/error.h"
#include "lucent/materials/albedo.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"

namespace lucent::python {
namespace {

using materials::DiffusionModel;
using materials::Material;
using materials::Rgb;

// The model a profile is evaluated in: given, else the one the material was fitted with, else the
// standard dipole (as `lucent profile`).
DiffusionModel model_for(const Material& material, const std::optional<std::string>& model) {
  const std::string name = model ? *model : (!material.model.empty() ? material.model : "dipole");
  return materials::parse_diffusion_model(name, "model", true);
}

materials::TableQuantity quantity_for(const std::string& quantity) {
  if (quantity == "exitance") return materials::TableQuantity::kExitance;
  if (quantity == "radiance") return materials::TableQuantity::kRadiance;
  throw Error("quantity: expected 'exitance' or 'radiance', got '" + quantity + "'");
}

Rgb rgb_from(const py::handle& value, const std::string& field) {
  try {
    const auto v = value.cast<std::array<double, 3>>();
    return {v[0], v[1], v[2]};
  } catch (const py::cast_error&) {
    throw Error(field + ": expected three numbers (R, G, B)");
  }
}

// A Material from keywords, checked as a material file is (material_from_json).
Material make_material(const std::string& name, double ior, const py::handle& sigma_a,
                       const py::handle& sigma_s_reduced, const py::handle& sigma_s,
                       const py::handle& g) {
  nlohmann::json doc = {{"format", "lucent-material"},
                        {"version", Material::kFormatVersion},
                        {"name", name},
                        {"ior", ior},
                        {"sigma_a", rgb_from(sigma_a, "sigma_a")},
                        {"sigma_s_reduced", rgb_from(sigma_s_reduced, "sigma_s_reduced")}};
  if (!sigma_s.is_none()) doc["sigma_s"] = rgb_from(sigma_s, "sigma_s");
  if (!g.is_none()) doc["g"] = rgb_from(g, "g");
  return materials::material_from_json(doc, "Material(" + name + ")");
}

py::array_t<double> profile(const Material& material, const Array& r_mm,
                            const std::optional<std::string>& model, const std::string& quantity) {
  const DiffusionModel m = model_for(material, model);
  const materials::TableQuantity q = quantity_for(quantity);
  const double* r = r_mm.data();
  const auto n = static_cast<std::size_t>(r_mm.size());
  for (std::size_t i = 0; i < n; ++i)
    if (!(std::isfinite(r[i]) && r[i] >= 0))
      throw Error("r_mm: expected finite radii >= 0 (mm), got " + std::to_string(r[i]));
  std::vector<py::ssize_t> shape(r_mm.shape(), r_mm.shape() + r_mm.ndim());
  shape.push_back(3);
  py::array_t<double> out(shape);
  double* v = out.mutable_data();
  // The table a tabulated profile needs is read (and its range checked) before the GIL goes.
  if (n > 0)
    for (int c = 0; c < 3; ++c) materials::radial_profile_value(material, c, m, q, r[0]);
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        v[3 * i + c] = materials::radial_profile_value(material, c, m, q, r[i]);
  }
  return out;
}

// S_d per channel for each row of a (N, 15) array of configurations (the columns of `lucent
// profile --configs`: x_i, n_i, w_i, x_o, n_o).
py::array_t<double> bssrdf(const Material& material, const Array& configs,
                           const std::optional<std::string>& model) {
  const DiffusionModel m = model_for(material, model);
  if (configs.ndim() != 2 || configs.shape(1) != 15)
    throw Error("configs: expected an (N, 15) array: x_i, n_i, w_i, x_o, n_o (mm, unit vectors)");
  const auto n = static_cast<std::size_t>(configs.shape(0));
  const double* c = configs.data();
  std::vector<materials::BssrdfConfig> list(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* row = c + 15 * i;
    const auto vec = [&](int k) { return materials::Vec3<double>{row[k], row[k + 1], row[k + 2]}; };
    list[i] = {vec(0), vec(3), vec(6), vec(9), vec(12)};
    for (int k : {3, 6, 12}) {
      const double len =
          std::sqrt(row[k] * row[k] + row[k + 1] * row[k + 1] + row[k + 2] * row[k + 2]);
      if (!(std::abs(len - 1) < 1e-6))
        throw Error("configs: row " + std::to_string(i) +
                    ": n_i, w_i and n_o must be unit vectors");
    }
  }
  py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{3}});
  double* v = out.mutable_data();
  py::gil_scoped_release release;
  for (std::size_t i = 0; i < n; ++i) {
    const std::array<double, 3> s = materials::evaluate_bssrdf(material, m, list[i]);
    for (int k = 0; k < 3; ++k) v[3 * i + k] = s[k];
  }
  return out;
}

template <typename F>
py::array_t<double> elementwise(const Array& x, F&& f) {
  py::array_t<double> out(std::vector<py::ssize_t>(x.shape(), x.shape() + x.ndim()));
  const double* in = x.data();
  double* v = out.mutable_data();
  for (py::ssize_t i = 0; i < x.size(); ++i) v[i] = f(in[i]);
  return out;
}

}  // namespace

void bind_materials(py::module_& m) {
  py::class_<Material>(m, "Material",
                       "A material: RGB coefficients (mm^-1), relative index, and what produced "
                       "them (a lucent-material file)")
      .def(py::init(&make_material), py::arg("name"), py::arg("ior"), py::arg("sigma_a"),
           py::arg("sigma_s_reduced"), py::arg("sigma_s") = py::none(), py::arg("g") = py::none(),
           "Material(name, ior, sigma_a, sigma_s_reduced, sigma_s=None, g=None): coefficients "
           "per channel in mm^-1, checked as a material file is")
      .def_static("load", &materials::load_material, py::arg("name_or_path"),
                  "a bundled material by name, or a lucent-material file")
      .def_static(
          "from_json",
          [](const py::object& doc, const std::string& source) {
            return materials::material_from_json(from_python(doc), source);
          },
          py::arg("document"), py::arg("source") = "document")
      .def(
          "save",
          [](const Material& mat, const std::filesystem::path& path) {
            materials::write_material(path, mat);
          },
          py::arg("path"), "writes the material file atomically")
      .def("to_json",
           [](const Material& mat) { return to_python(materials::material_to_json(mat)); })
      .def_readwrite("name", &Material::name)
      .def_readonly("ior", &Material::ior)
      .def_readonly("sigma_a", &Material::sigma_a, "absorption, mm^-1 (R, G, B)")
      .def_readonly("sigma_s_reduced", &Material::sigma_s_reduced,
                    "reduced scattering sigma_s (1 - g), mm^-1")
      .def_readonly("sigma_s", &Material::sigma_s, "unreduced scattering, mm^-1, or None")
      .def_readonly("g", &Material::g, "Henyey-Greenstein mean cosine, or None")
      .def_readonly("model", &Material::model, "the model it was fitted with, or ''")
      .def_readonly("adequate_model", &Material::adequate_model)
      .def_readonly("fallback_model", &Material::fallback_model)
      .def_property_readonly("uncertainty",
                             [](const Material& mat) { return to_python(mat.uncertainty); })
      .def_property_readonly("provenance",
                             [](const Material& mat) { return to_python(mat.provenance); })
      .def("__repr__", [](const Material& mat) { return "<lucent.Material " + mat.name + ">"; });

  m.def("library", &materials::library_material_names, "the bundled materials' names");
  m.def("profile", &profile, py::arg("material"), py::arg("r_mm"), py::arg("model") = py::none(),
        py::arg("quantity") = "exitance",
        "the radial profile per mm^2 per unit power entering, normal incidence, at radii r_mm: "
        "an array of r_mm's shape plus (3,) (R, G, B). model: dipole, ddipole or tabulated "
        "(default: the material's fitted model, else dipole); quantity: exitance (R(r)) or "
        "radiance (pi L along the normal), as `lucent profile`");
  m.def(
      "total_reflectance",
      [](const Material& mat, const std::optional<std::string>& model) {
        const DiffusionModel dm = model_for(mat, model);
        return std::array<double, 3>{materials::total_diffuse_reflectance(mat, 0, dm),
                                     materials::total_diffuse_reflectance(mat, 1, dm),
                                     materials::total_diffuse_reflectance(mat, 2, dm)};
      },
      py::arg("material"), py::arg("model") = py::none(),
      "the total diffuse reflectance per channel, per unit power entering (`--total`)");
  m.def("bssrdf", &bssrdf, py::arg("material"), py::arg("configs"), py::arg("model") = py::none(),
        "S_d per mm^2 per sr for each row of an (N, 15) array x_i, n_i, w_i, x_o, n_o (mm; unit "
        "vectors, w_i toward the light): an (N, 3) array. model: dipole or ddipole");
  m.def(
      "fresnel_reflectance",
      [](const Array& cos_i, double eta) {
        return elementwise(cos_i,
                           [eta](double c) { return materials::fresnel_reflectance(c, eta); });
      },
      py::arg("cos_i"), py::arg("eta"),
      "unpolarised Fresnel reflectance at incidence cosines cos_i, relative index eta");
  m.def("diffuse_fresnel_reflectance", &materials::diffuse_fresnel_reflectance<double>,
        py::arg("eta"), "the cosine-weighted hemispherical mean of the Fresnel reflectance");
  m.def(
      "reduced_albedo_from_total_reflectance",
      [](const Array& total, double eta) {
        return elementwise(total, [eta](double r) {
          return materials::reduced_albedo_from_total_reflectance(r, eta);
        });
      },
      py::arg("total_reflectance"), py::arg("eta"),
      "alpha' whose standard-dipole total diffuse reflectance is the given one");
  m.def(
      "coefficients_from_diffuse_colour",
      [](double colour, double mean_free_path_mm, double eta) {
        const materials::ReducedCoefficients c =
            materials::coefficients_from_diffuse_colour(colour, mean_free_path_mm, eta);
        return py::make_tuple(c.sigma_a, c.sigma_s_reduced);
      },
      py::arg("diffuse_reflectance"), py::arg("diffuse_mean_free_path_mm"), py::arg("eta"),
      "(sigma_a, sigma_s') in mm^-1 from a diffuse colour and mean free path (Jensen and Buhler)");
}

}  // namespace lucent::python
