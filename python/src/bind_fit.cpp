// lucent.fit: profiles -> the material with its uncertainty, report and adequacy, the way
// `lucent fit` fits (the same options, the same tables found or built: cli/fit_tables.h).
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>

#include "bindings.h"
#include "fit_beam.h"
#include "fit_tables.h"
#include "lucent/core/error.h"
#include "lucent/fit/fit.h"
#include "lucent/materials/transport_table.h"

namespace lucent::python {
namespace {

using fit::FitOptions;
using fit::ProfileData;

struct FitKeywords {
  std::string model = "auto", quality = "balanced", loss = "none";
  double loss_scale = 1, g = 0, beam_sigma_mm = 0;
  std::optional<double> ior, exclude_radius_mm, thickness_mm;
  bool fit_ior = false, relative = false, fit_thickness = false, allow_unconverged = false;
  std::optional<std::string> table, oblique_table, beam_image;
  double beam_pixel_mm = 0;
  std::uint64_t table_photons = 1'000'000, slab_photons = 200'000, oblique_photons = 1'000'000;
  std::string name = "fit";
};

// The options `lucent fit` makes of its flags (cli/fit_command.cpp to_options), named as here.
FitOptions to_options(const FitKeywords& k) {
  FitOptions o;
  o.model = fit::parse_fit_model(k.model, "model");
  if (!(k.g >= 0 && k.g <= 0.99)) throw Error("g: expected a Henyey-Greenstein g in [0, 0.99]");
  o.g = k.g;
  o.quality = fit::parse_quality(k.quality, "quality");
  if (k.loss == "huber")
    o.loss = fit::LossKind::kHuber;
  else if (k.loss == "cauchy")
    o.loss = fit::LossKind::kCauchy;
  else if (k.loss != "none")
    throw Error("loss: expected none, huber or cauchy, got '" + k.loss + "'");
  if (!(k.loss_scale > 0 && k.loss_scale <= 1e6))
    throw Error("loss_scale: expected a number in (0, 1e6] standard errors");
  o.loss_scale = k.loss_scale;
  if (k.exclude_radius_mm && !(*k.exclude_radius_mm >= 0 && *k.exclude_radius_mm < 1e6))
    throw Error("exclude_radius_mm: expected a radius >= 0 (mm)");
  o.exclude_radius_mm = k.exclude_radius_mm;
  if (k.thickness_mm && !(*k.thickness_mm > 0 && *k.thickness_mm < 1e6))
    throw Error("thickness_mm: expected a thickness > 0 (mm)");
  o.thickness_mm = k.thickness_mm;
  o.fit_thickness = k.fit_thickness;
  if (o.fit_thickness && o.thickness_mm)
    throw Error("fit_thickness: the thickness is either given (thickness_mm) or fitted, not both");
  if (!(k.beam_sigma_mm >= 0 && k.beam_sigma_mm < 1e3))
    throw Error("beam_sigma_mm: expected a beam sigma >= 0 (mm)");
  o.beam_sigma_mm = k.beam_sigma_mm;
  if (k.ior && !(*k.ior > 0 && *k.ior <= 4))
    throw Error("ior: expected a relative index in (0, 4]");
  o.ior = k.ior;
  o.fit_ior = k.fit_ior;
  if (k.relative) o.relative = true;
  o.allow_unconverged = k.allow_unconverged;
  return o;
}

// What lucent.fit returns: the material, the numbers per channel, and the report `--report`
// writes.
struct PyFitResult {
  materials::Material material;
  fit::FitResult result;
  nlohmann::json report;
};

PyFitResult run_fit(std::vector<ProfileData> data, const FitKeywords& k,
                    const std::function<void(const std::string&, double)>& progress) {
  if (data.empty()) throw Error("profiles: expected at least one lucent.Profile");
  FitOptions options = to_options(k);
  for (const ProfileData& d : data)
    if (!d.eta && !options.ior && !options.fit_ior)
      throw Error("ior: required with " + d.source +
                  ", which carries no index (no ior= or eta= in its comment lines)");
  if (k.beam_image) {
    if (k.beam_sigma_mm > 0)
      throw Error("beam_image: the beam is given either as an image or as beam_sigma_mm");
    cli::use_beam_image(data, *k.beam_image, k.beam_pixel_mm);
  }
  materials::TransportTable given;
  std::optional<materials::TransportTable> oblique;
  PyFitResult out;
  {
    py::gil_scoped_release release;  // tables may be built here: minutes
    if (k.table) {
      given = materials::read_transport_table(*k.table);
      if (given.partial || given.grid.phi_bins > 1 || given.slab())
        throw Error("table " + *k.table +
                    ": expected a whole radial table (not a shard, an "
                    "oblique table or a slab's)");
      options.table = &given;
    }
    if (const materials::TransportTable* radial =
            cli::radial_table_for(data, options, k.table_photons, true))
      options.table = radial;
    options.slab = cli::slab_nodes_for(data, options, k.slab_photons, true);
    oblique = cli::oblique_table_for(data, options, k.oblique_table.value_or(""), k.oblique_photons,
                                     true);
    if (oblique) options.oblique_table = &*oblique;
    if (progress)
      options.progress = [&](const std::string& stage, double done) {
        py::gil_scoped_acquire hold;
        progress(stage, done);
      };
    out.result = fit::fit_profiles(data, options);
    out.material = fit::fitted_material(out.result, data, options, k.name);
    out.report = fit::fit_report(out.result, data, options);
  }
  return out;
}

// Per channel (R, G, B) one field of the chosen model's fit.
template <typename F>
std::array<double, 3> per_channel(const PyFitResult& r, F&& field) {
  std::array<double, 3> out{};
  for (int c = 0; c < 3; ++c) out[c] = field(r.result.chosen.channels[c]);
  return out;
}

}  // namespace

void bind_fit(py::module_& m) {
  using C = fit::ChannelFit;
  py::class_<PyFitResult>(m, "FitResult",
                          "A fit: the material, the coefficients' uncertainty per channel "
                          "(statistical, systematic, total: 1 SD, mm^-1), the report, adequacy")
      .def_readonly("material", &PyFitResult::material)
      .def_property_readonly("report", [](const PyFitResult& r) { return to_python(r.report); })
      .def_property_readonly(
          "model", [](const PyFitResult& r) { return fit::to_string(r.result.chosen.model); })
      .def_property_readonly("reason", [](const PyFitResult& r) { return r.result.reason; })
      .def_property_readonly("converged",
                             [](const PyFitResult& r) { return r.result.chosen.converged; })
      .def_property_readonly("eta", [](const PyFitResult& r) { return r.result.chosen.eta; })
      .def_property_readonly(
          "sigma_a",
          [](const PyFitResult& r) { return per_channel(r, [](const C& c) { return c.sigma_a; }); })
      .def_property_readonly("sigma_s_reduced",
                             [](const PyFitResult& r) {
                               return per_channel(r, [](const C& c) { return c.sigma_s_reduced; });
                             })
      .def_property_readonly("sd_sigma_a",
                             [](const PyFitResult& r) {
                               return per_channel(r, [](const C& c) { return c.sd_sigma_a; });
                             })
      .def_property_readonly("sd_sigma_s_reduced",
                             [](const PyFitResult& r) {
                               return per_channel(r,
                                                  [](const C& c) { return c.sd_sigma_s_reduced; });
                             })
      .def_property_readonly("sd_stat_sigma_a",
                             [](const PyFitResult& r) {
                               return per_channel(r, [](const C& c) { return c.sd_stat_sigma_a; });
                             })
      .def_property_readonly("sd_stat_sigma_s_reduced",
                             [](const PyFitResult& r) {
                               return per_channel(
                                   r, [](const C& c) { return c.sd_stat_sigma_s_reduced; });
                             })
      .def_property_readonly("sd_sys_sigma_a",
                             [](const PyFitResult& r) {
                               return per_channel(r, [](const C& c) { return c.sd_sys_sigma_a; });
                             })
      .def_property_readonly("sd_sys_sigma_s_reduced",
                             [](const PyFitResult& r) {
                               return per_channel(
                                   r, [](const C& c) { return c.sd_sys_sigma_s_reduced; });
                             })
      .def_property_readonly("reduced_chi2",
                             [](const PyFitResult& r) {
                               return per_channel(r, [](const C& c) { return c.reduced_chi2; });
                             })
      .def_property_readonly("adequate_model",
                             [](const PyFitResult& r) { return r.result.adequate_model; })
      .def_property_readonly("fallback_model",
                             [](const PyFitResult& r) { return r.result.fallback_model; })
      .def_property_readonly("adequacy",
                             [](const PyFitResult& r) {
                               return to_python(r.report.value("adequacy", nlohmann::json()));
                             })
      .def_property_readonly("notes", [](const PyFitResult& r) { return r.result.notes; })
      .def_property_readonly("warnings", [](const PyFitResult& r) { return r.result.warnings; })
      .def("__repr__", [](const PyFitResult& r) {
        return "<lucent.FitResult " + fit::to_string(r.result.chosen.model) + ">";
      });

  m.def(
      "fit",
      [](const std::vector<ProfileData>& profiles, const std::string& model,
         const std::string& quality, std::optional<double> ior, bool fit_ior, double g,
         bool relative, const std::string& loss, double loss_scale,
         std::optional<double> exclude_radius_mm, std::optional<double> thickness_mm,
         bool fit_thickness, double beam_sigma_mm, std::optional<std::string> beam_image,
         double beam_pixel_mm, std::optional<std::string> table,
         std::optional<std::string> oblique_table, bool allow_unconverged, const std::string& name,
         std::uint64_t table_photons, std::uint64_t slab_photons, std::uint64_t oblique_photons,
         const std::function<void(const std::string&, double)>& progress) {
        FitKeywords k;
        k.model = model, k.quality = quality, k.ior = ior, k.fit_ior = fit_ior, k.g = g;
        k.relative = relative, k.loss = loss, k.loss_scale = loss_scale;
        k.exclude_radius_mm = exclude_radius_mm, k.thickness_mm = thickness_mm;
        k.fit_thickness = fit_thickness, k.beam_sigma_mm = beam_sigma_mm;
        k.beam_image = beam_image, k.beam_pixel_mm = beam_pixel_mm;
        k.table = table, k.oblique_table = oblique_table;
        k.allow_unconverged = allow_unconverged, k.name = name;
        k.table_photons = table_photons, k.slab_photons = slab_photons;
        k.oblique_photons = oblique_photons;
        return run_fit(profiles, k, progress);
      },
      py::arg("profiles"), py::kw_only(), py::arg("model") = "auto",
      py::arg("quality") = "balanced", py::arg("ior") = py::none(), py::arg("fit_ior") = false,
      py::arg("g") = 0.0, py::arg("relative") = false, py::arg("loss") = "none",
      py::arg("loss_scale") = 1.0, py::arg("exclude_radius_mm") = py::none(),
      py::arg("thickness_mm") = py::none(), py::arg("fit_thickness") = false,
      py::arg("beam_sigma_mm") = 0.0, py::arg("beam_image") = py::none(),
      py::arg("beam_pixel_mm") = 0.0, py::arg("table") = py::none(),
      py::arg("oblique_table") = py::none(), py::arg("allow_unconverged") = false,
      py::arg("name") = "fit", py::arg("table_photons") = 1'000'000,
      py::arg("slab_photons") = 200'000, py::arg("oblique_photons") = 1'000'000,
      py::arg("progress") = nullptr,
      "fits the profiles of one material jointly, as `lucent fit` does with the same options "
      "(the flags' names with _ for -): a FitResult. progress(stage, done) is called as each "
      "stage starts. The GIL is released while it runs");
}

}  // namespace lucent::python
