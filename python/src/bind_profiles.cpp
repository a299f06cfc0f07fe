// lucent.Profile (what a fit consumes: fit::ProfileData) read from a file, made from NumPy arrays,
// or measured from a capture by lucent.acquire.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <random>

#include "bindings.h"
#include "lucent/acquire/acquire.h"
#include "lucent/core/error.h"
#include "lucent/fit/fit_data.h"

namespace lucent::python {
namespace {

using fit::ProfileData;

// (n, 3) from per-channel vectors.
py::array_t<double> columns(const std::array<std::vector<double>, 3>& v) {
  const auto n = static_cast<py::ssize_t>(v[0].size());
  py::array_t<double> out({n, py::ssize_t{3}});
  double* o = out.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) o[3 * i + c] = v[c][static_cast<std::size_t>(i)];
  return out;
}

py::array_t<double> vector_array(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

// A column of N values or an (N, 3) array, as three channels of N.
std::array<std::vector<double>, 3> channels_of(const Array& a, std::size_t n,
                                               const std::string& name) {
  std::array<std::vector<double>, 3> out;
  const double* d = a.data();
  if (a.ndim() == 1 && static_cast<std::size_t>(a.shape(0)) == n) {
    for (auto& c : out) c.assign(d, d + n);
  } else if (a.ndim() == 2 && static_cast<std::size_t>(a.shape(0)) == n && a.shape(1) == 3) {
    for (int c = 0; c < 3; ++c) {
      out[c].resize(n);
      for (std::size_t i = 0; i < n; ++i) out[c][i] = d[3 * i + c];
    }
  } else {
    throw Error(name + ": expected " + std::to_string(n) + " values (one per radius) or an (" +
                std::to_string(n) + ", 3) array (R, G, B)");
  }
  return out;
}

// A profile from arrays, checked as the CSV reader checks a file: radii finite, >= 0 and
// increasing; values finite; standard errors finite and > 0.
ProfileData profile_from_arrays(const Array& r_mm, const Array& value,
                                const std::optional<Array>& standard_error,
                                std::optional<double> ior, const std::string& quantity,
                                bool per_incident_power, bool calibrated,
                                const std::string& source) {
  if (r_mm.ndim() != 1 || r_mm.size() < 2)
    throw Error(source + ": r_mm: expected a 1-D array of radii (mm)");
  const auto n = static_cast<std::size_t>(r_mm.size());
  ProfileData p;
  p.source = source;
  p.radial.r_mm.assign(r_mm.data(), r_mm.data() + n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = p.radial.r_mm[i];
    if (!(std::isfinite(r) && r >= 0) || (i > 0 && !(r > p.radial.r_mm[i - 1])))
      throw Error(source + ": r_mm: expected finite, increasing radii >= 0 (mm); row " +
                  std::to_string(i) + " is " + std::to_string(r));
  }
  p.radial.r_inner_mm = p.radial.r_mm;
  p.radial.r_outer_mm = p.radial.r_mm;
  p.radial.value = channels_of(value, n, source + ": value");
  if (standard_error) {
    p.radial.standard_error = channels_of(*standard_error, n, source + ": standard_error");
  } else {
    for (int c = 0; c < 3; ++c)
      for (double v : p.radial.value[c]) p.radial.standard_error[c].push_back(0.05 * std::abs(v));
    p.notes.push_back("no standard errors given: 5% of each value assumed");
  }
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(p.radial.value[c][i]))
        throw Error(source + ": value: row " + std::to_string(i) + " is not finite");
      if (!(std::isfinite(p.radial.standard_error[c][i]) && p.radial.standard_error[c][i] > 0))
        throw Error(source + ": standard_error: row " + std::to_string(i) +
                    ": expected a finite value > 0");
    }
  if (ior) {
    if (!(*ior > 0 && *ior <= 4))
      throw Error(source + ": ior: expected a relative index in (0, 4]");
    p.eta = *ior;
  }
  if (quantity == "exitance")
    p.exitance = true;
  else if (quantity != "radiance")
    throw Error(source + ": quantity: expected 'exitance' or 'radiance', got '" + quantity + "'");
  p.per_incident_power = per_incident_power;
  p.calibrated = calibrated;
  return p;
}

ProfileData acquire_profile(const std::filesystem::path& capture_json,
                            const std::optional<std::filesystem::path>& out_dir, int bins,
                            bool log_bins, std::optional<double> radius_mm) {
  acquire::AcquireOptions options;
  options.bins = bins;
  options.log_bins = log_bins;
  options.radius_mm = radius_mm;
  std::filesystem::path dir;
  bool temporary = false;
  if (out_dir) {
    dir = *out_dir;
  } else {  // a private folder, removed after the profile is read
    std::random_device device;
    dir = std::filesystem::temp_directory_path() /
          ("lucent-acquire-" + std::to_string(device()) + std::to_string(device()));
    temporary = true;
  }
  try {
    {
      py::gil_scoped_release release;
      acquire::run_acquire(capture_json, dir, options);
    }
    ProfileData p = fit::load_profile_data(dir / "profile.json");
    if (temporary) {  // the folder goes: the profile is named after the capture
      std::filesystem::remove_all(dir);
      p.source = capture_json.string();
    }
    return p;
  } catch (...) {
    std::error_code ignored;
    if (temporary) std::filesystem::remove_all(dir, ignored);
    throw;
  }
}

}  // namespace

void bind_profiles(py::module_& m) {
  py::class_<ProfileData>(m, "Profile",
                          "One measured profile (a capture's radial bins, and its 2D samples at "
                          "oblique incidence): what lucent.fit consumes")
      .def(py::init(&profile_from_arrays), py::arg("r_mm"), py::arg("value"),
           py::arg("standard_error") = py::none(), py::arg("ior") = py::none(),
           py::arg("quantity") = "radiance", py::arg("per_incident_power") = false,
           py::arg("calibrated") = true, py::arg("source") = "arrays",
           "Profile(r_mm, value, standard_error=None, ior=None, quantity='radiance', ...): "
           "values per mm^2 per unit power (entering, or incident with per_incident_power), one "
           "column or (N, 3); without standard errors 5% is assumed, as for a CSV")
      .def_static("load", &fit::load_profile_data, py::arg("path"),
                  "a profile.json (lucent acquire) or a radial CSV (lucent profile, simulate)")
      .def_readonly("source", &ProfileData::source)
      .def_readonly("eta", &ProfileData::eta, "relative index, or None")
      .def_readonly("calibrated", &ProfileData::calibrated)
      .def_readonly("incidence_deg", &ProfileData::incidence_polar_deg)
      .def_readonly("view_deg", &ProfileData::view_deg)
      .def_readonly("thickness_mm", &ProfileData::thickness_mm)
      .def_readonly("notes", &ProfileData::notes)
      .def_property_readonly(
          "quantity", [](const ProfileData& p) { return p.exitance ? "exitance" : "radiance"; })
      .def_property_readonly("r_mm",
                             [](const ProfileData& p) { return vector_array(p.radial.r_mm); })
      .def_property_readonly(
          "value", [](const ProfileData& p) { return columns(p.radial.value); },
          "(N, 3): per mm^2 per unit power")
      .def_property_readonly("standard_error",
                             [](const ProfileData& p) { return columns(p.radial.standard_error); })
      .def_property_readonly("samples_2d",
                             [](const ProfileData& p) -> py::object {
                               if (!p.samples_2d) return py::none();
                               py::dict d;
                               d["x_mm"] = vector_array(p.samples_2d->x_mm);
                               d["y_mm"] = vector_array(p.samples_2d->y_mm);
                               d["value"] = columns(p.samples_2d->value);
                               d["standard_error"] = columns(p.samples_2d->standard_error);
                               return d;
                             })
      .def("__repr__", [](const ProfileData& p) {
        return "<lucent.Profile " + p.source + ": " + std::to_string(p.radial.size()) + " bins>";
      });

  m.def("acquire", &acquire_profile, py::arg("capture_json"), py::arg("out_dir") = py::none(),
        py::arg("bins") = 150, py::arg("log_bins") = false, py::arg("radius_mm") = py::none(),
        "a capture (capture.json: brackets or an HDR image) -> its Profile, as `lucent acquire` "
        "(out_dir: also keep what it writes there: capture.exr, profile.json/csv, acquire.png)");
}

}  // namespace lucent::python
