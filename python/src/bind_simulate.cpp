// lucent.simulate (the Monte Carlo capture rig: arrays, and a capture folder when asked) and
// lucent.export_material (a material in another renderer's terms).
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "bindings.h"
#include "lucent/acquire/simulate.h"
#include "lucent/core/error.h"
#include "lucent/materials/export.h"

namespace lucent::python {
namespace {

using acquire::PhotonTransportResult;

// The transport's results as arrays: radial exitance per channel (mm^-2 per unit incident power)
// with its standard errors, totals, and the camera image (size, size, 3; mm^-2 sr^-1).
py::dict arrays_of(const PhotonTransportResult& t, const std::vector<std::string>& files) {
  const auto bins = static_cast<py::ssize_t>(t.bins.size());
  py::array_t<double> r_inner(bins), r_outer(bins), r(bins);
  py::array_t<double> exitance({bins, py::ssize_t{3}}), exitance_se({bins, py::ssize_t{3}});
  for (py::ssize_t b = 0; b < bins; ++b) {
    r_inner.mutable_at(b) = t.bins[b].r_inner_mm;
    r_outer.mutable_at(b) = t.bins[b].r_outer_mm;
    r.mutable_at(b) = t.bins[b].r_centre_mm;
  }
  const auto nan = std::numeric_limits<double>::quiet_NaN();
  py::dict totals;
  for (const char* name :
       {"diffuse_reflectance", "specular_reflectance", "transmittance", "absorbed"}) {
    totals[name] = py::array_t<double>(3);
    totals[(std::string(name) + "_se").c_str()] = py::array_t<double>(3);
  }
  const int size = t.options.size;
  const bool image = t.options.image;
  py::array_t<double> pixels(
      {py::ssize_t{image ? size : 0}, py::ssize_t{image ? size : 0}, py::ssize_t{3}});
  for (int c = 0; c < 3; ++c) {
    const acquire::ChannelTransportResult& ch = t.channels[c];
    const bool run = ch.photons > 0;
    for (py::ssize_t b = 0; b < bins; ++b) {
      exitance.mutable_at(b, c) = run ? ch.exitance[b].value : nan;
      exitance_se.mutable_at(b, c) = run ? ch.exitance[b].standard_error : nan;
    }
    const auto put = [&](const char* name, const acquire::Estimate& e) {
      totals[name].cast<py::array_t<double>>().mutable_at(c) = run ? e.value : nan;
      totals[(std::string(name) + "_se").c_str()].cast<py::array_t<double>>().mutable_at(c) =
          run ? e.standard_error : nan;
    };
    put("diffuse_reflectance", ch.diffuse_reflectance);
    put("specular_reflectance", ch.specular_reflectance);
    put("transmittance", ch.transmittance);
    put("absorbed", ch.absorbed);
    if (image)
      for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i)
          pixels.mutable_at(j, i, c) =
              run && !ch.image.empty() ? ch.image[std::size_t(j) * std::size_t(size) + i] : nan;
  }
  py::dict out;
  out["r_inner_mm"] = r_inner, out["r_outer_mm"] = r_outer, out["r_mm"] = r;
  out["exitance"] = exitance, out["exitance_se"] = exitance_se;
  for (auto item : totals) out[item.first] = item.second;
  out["image"] = pixels;
  out["pixel_mm"] = t.options.pixel_mm;
  out["mean_interactions"] =
      py::make_tuple(t.channels[0].mean_interactions, t.channels[1].mean_interactions,
                     t.channels[2].mean_interactions);
  out["files"] = files;
  return out;
}

py::dict simulate(const materials::Material& material,
                  const std::optional<std::filesystem::path>& out_dir, std::uint64_t photons,
                  std::uint64_t seed, int threads, std::optional<double> thickness_mm,
                  const std::string& side, double beam_sigma_mm, double incidence_deg,
                  double azimuth_deg, double view_deg, std::optional<int> size,
                  std::optional<double> pixel_mm, bool image, double lens_blur_mm, double glare,
                  double glare_radius_mm, bool noise,
                  const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  acquire::SimulateOptions o;
  o.material = material;
  acquire::PhotonTransportOptions& t = o.transport;
  t.photons = photons, t.seed = seed, t.threads = threads;
  if (thickness_mm) t.thickness_mm = *thickness_mm;
  if (side != "reflected" && side != "transmitted")
    throw Error("side: expected reflected (the lit side) or transmitted (the far side), got '" +
                side + "'");
  t.far_side = side == "transmitted";
  if (t.far_side && !thickness_mm) throw Error("side transmitted: the far side needs thickness_mm");
  t.beam_sigma_mm = beam_sigma_mm, t.incidence_deg = incidence_deg, t.azimuth_deg = azimuth_deg;
  t.view_deg = view_deg;
  const acquire::SimulationField field = acquire::default_simulation_field(
      material, size.value_or(128), pixel_mm.value_or(0.1), size.has_value(), pixel_mm.has_value());
  t.size = field.size, t.pixel_mm = field.pixel_mm;
  t.image = image || out_dir.has_value();
  o.lens_blur_mm = lens_blur_mm, o.glare = glare, o.glare_radius_mm = glare_radius_mm;
  o.camera.noise = noise;
  const acquire::PhotonTransportProgress told =
      progress ? acquire::PhotonTransportProgress([&](std::uint64_t done, std::uint64_t total) {
        py::gil_scoped_acquire hold;
        progress(done, total);
      })
               : acquire::PhotonTransportProgress();
  py::gil_scoped_release release;
  if (out_dir) {
    // The whole rig: brackets, white reference, dark frame, capture.json, truth (lucent simulate).
    const acquire::SimulateSummary s = acquire::run_simulation(o, *out_dir, told);
    py::gil_scoped_acquire hold;
    return arrays_of(s.transport, s.files);
  }
  for (int c = 0; c < 3; ++c) t.media[c] = material.medium(c);
  const PhotonTransportResult result = acquire::simulate_photon_transport(t, told);
  py::gil_scoped_acquire hold;
  return arrays_of(result, {});
}

}  // namespace

void bind_simulate(py::module_& m) {
  m.def("simulate", &simulate, py::arg("material"), py::arg("out_dir") = py::none(), py::kw_only(),
        py::arg("photons") = 1'000'000, py::arg("seed") = 1, py::arg("threads") = 0,
        py::arg("thickness_mm") = py::none(), py::arg("side") = "reflected",
        py::arg("beam_sigma_mm") = 0.0, py::arg("incidence_deg") = 0.0,
        py::arg("azimuth_deg") = 0.0, py::arg("view_deg") = 0.0, py::arg("size") = py::none(),
        py::arg("pixel_mm") = py::none(), py::arg("image") = true, py::arg("lens_blur_mm") = 0.0,
        py::arg("glare") = 0.0, py::arg("glare_radius_mm") = 1.0, py::arg("noise") = true,
        py::arg("progress") = nullptr,
        "Monte Carlo photon transport in a slab of the material (semi-infinite unless "
        "thickness_mm), lit by a pencil (or Gaussian) beam: a dict of arrays (radial exitance "
        "per mm^2 per unit incident power with standard errors, totals, the camera image in "
        "mm^-2 sr^-1). With out_dir, the whole capture folder `lucent simulate` writes (brackets, "
        "white reference, dark frame, capture.json, truth). The field defaults as the CLI's; the "
        "same numbers for a seed whatever the threads. The GIL is released while it runs");
  m.def(
      "export_material",
      [](const materials::Material& material, const std::string& target,
         const std::string& scene_unit) {
        const materials::ExportResult r =
            materials::export_material(material, materials::parse_export_target(target),
                                       materials::millimetres_per_unit(scene_unit));
        py::dict out;
        out["text"] = r.text;
        out["losses"] = r.losses;
        out["extension"] = materials::export_extension(materials::parse_export_target(target));
        out["sigma_a_back"] = r.sigma_a_back;
        out["sigma_s_reduced_back"] = r.sigma_s_reduced_back;
        return out;
      },
      py::arg("material"), py::arg("target"), py::arg("scene_unit") = "mm",
      "the material in another renderer's terms (`lucent export`): target pbrt, mitsuba, "
      "materialx, openpbr or gltf; scene_unit mm, cm or m. A dict: the file's text, what the "
      "target cannot carry, and the coefficients read back (mm^-1)");
}

}  // namespace lucent::python
