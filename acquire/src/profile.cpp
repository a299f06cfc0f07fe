#include "lucent/acquire/profile.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

#include "lucent/acquire/hdr_merge.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "slab_fields.h"

namespace lucent::acquire {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

constexpr const char* kCalibratedUnits = "per mm^2 (pi L / beam power)";
constexpr const char* kRelativeUnits = "relative (pi L, uncalibrated)";

template <typename T>
ordered_json per_channel(const std::array<std::vector<T>, 3>& values) {
  return ordered_json::array({values[0], values[1], values[2]});
}

// Objects indented, arrays of numbers on one line: a person can read the structure and the file
// stays small (a 2D profile has one entry per pixel).
void dump_compact(const ordered_json& value, int indent, std::string& out) {
  const std::string pad(std::size_t(indent) + 2, ' ');
  if (value.is_object() && !value.empty()) {
    out += "{\n";
    bool first = true;
    for (const auto& [key, item] : value.items()) {
      if (!first) out += ",\n";
      first = false;
      out += pad + ordered_json(key).dump() + ": ";
      dump_compact(item, indent + 2, out);
    }
    out += "\n" + std::string(std::size_t(indent), ' ') + "}";
  } else if (value.is_array() && std::any_of(value.begin(), value.end(), [](const ordered_json& e) {
               return e.is_structured();
             })) {
    out += "[\n";
    for (std::size_t i = 0; i < value.size(); ++i) {
      out += pad;
      dump_compact(value[i], indent + 2, out);
      out += i + 1 < value.size() ? ",\n" : "\n";
    }
    out += std::string(std::size_t(indent), ' ') + "]";
  } else {
    out += value.dump();
  }
}

ordered_json profile_to_ordered_json(const Profile& p) {
  ordered_json doc;
  doc["format"] = "lucent-profile";
  doc["version"] = Profile::kFormatVersion;
  doc["calibrated"] = p.calibrated;
  doc["units"] = p.units();
  doc["capture"] = p.capture;
  doc["pixel_pitch_mm"] = p.pixel_pitch_mm;
  doc["incidence"] = {{"polar_deg", p.incidence_polar_deg},
                      {"azimuth_deg", p.incidence_azimuth_deg}};
  doc["view_deg"] = p.view_deg;
  if (p.ior) doc["ior"] = *p.ior;
  if (p.thickness_mm) doc["thickness_mm"] = *p.thickness_mm;
  if (p.thickness_mm) doc["side"] = p.transmitted ? "transmitted" : "reflected";
  if (!p.response_r_mm.empty())
    doc["system_response"] = {{"r_mm", p.response_r_mm},
                              {"value", p.response_value},
                              {"rms_radius_mm", p.response_rms_mm},
                              {"units", "per mm^2, unit integral over the plane"},
                              {"source", "white reference"}};
  doc["beam_point_px"] = {p.beam_point_px[0], p.beam_point_px[1]};
  doc["beam_point_source"] = p.beam_point_source;
  doc["beam_power"] = p.beam_power ? ordered_json(*p.beam_power) : ordered_json(nullptr);
  const RadialProfile& r = p.radial;
  doc["radial"] = {{"r_mm", r.r_mm},
                   {"r_inner_mm", r.r_inner_mm},
                   {"r_outer_mm", r.r_outer_mm},
                   {"value", per_channel(r.value)},
                   {"standard_error", per_channel(r.standard_error)},
                   {"count", per_channel(r.count)}};
  if (p.samples_2d) {
    const Samples2d& s = *p.samples_2d;
    doc["samples_2d"] = {{"x_mm", s.x_mm},
                         {"y_mm", s.y_mm},
                         {"value", per_channel(s.value)},
                         {"standard_error", per_channel(s.standard_error)}};
  }
  doc["masked"] = {{"saturated", p.masked.saturated},
                   {"black", p.masked.black},
                   {"non_finite", p.masked.non_finite}};
  doc["provenance"] = ordered_json::parse(p.provenance.is_null() ? "{}" : p.provenance.dump());
  return doc;
}

class FieldReader {
 public:
  explicit FieldReader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw Error(source_ + ": field '" + field + "': " + what);
  }

  const json& get(const json& object, const std::string& key, const std::string& field) const {
    if (!object.contains(key)) fail(field, "missing");
    return object[key];
  }

  double number(const json& value, const std::string& field) const {
    if (!value.is_number())
      fail(field, "expected a number, found " + std::string(value.type_name()));
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(field, "expected a finite number");
    return v;
  }

  std::vector<double> numbers(const json& value, const std::string& field,
                              std::optional<std::size_t> length = std::nullopt) const {
    if (!value.is_array())
      fail(field, "expected an array of numbers, found " + std::string(value.type_name()));
    if (length && value.size() != *length) {
      fail(field, "expected " + std::to_string(*length) + " numbers, found " +
                      std::to_string(value.size()));
    }
    std::vector<double> out;
    out.reserve(value.size());
    for (std::size_t i = 0; i < value.size(); ++i) {
      out.push_back(number(value[i], field + "[" + std::to_string(i) + "]"));
    }
    return out;
  }

  std::vector<std::int64_t> counts(const json& value, const std::string& field,
                                   std::size_t length) const {
    if (!value.is_array() || value.size() != length) {
      fail(field,
           "expected " + std::to_string(length) + " non-negative integers, found " +
               (value.is_array() ? std::to_string(value.size()) : std::string(value.type_name())));
    }
    std::vector<std::int64_t> out;
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (!value[i].is_number_integer() || value[i].get<std::int64_t>() < 0) {
        fail(field + "[" + std::to_string(i) + "]", "expected a non-negative integer");
      }
      out.push_back(value[i].get<std::int64_t>());
    }
    return out;
  }

  // [[R...], [G...], [B...]], each of `length` numbers.
  std::array<std::vector<double>, 3> channels(const json& value, const std::string& field,
                                              std::size_t length, const std::string& per) const {
    if (!value.is_array() || value.size() != 3) fail(field, "expected 3 arrays (R, G, B)");
    std::array<std::vector<double>, 3> out;
    for (int c = 0; c < 3; ++c) {
      const std::string name = field + "[" + std::to_string(c) + "]";
      if (!value[c].is_array() || value[c].size() != length) {
        fail(name, "expected " + std::to_string(length) + " numbers (one per " + per + "), found " +
                       (value[c].is_array() ? std::to_string(value[c].size())
                                            : std::string(value[c].type_name())));
      }
      out[c] = numbers(value[c], name);
    }
    return out;
  }

  void only_known(const json& object, const std::string& prefix,
                  const std::set<std::string>& known) const {
    for (const auto& [key, item] : object.items()) {
      if (!known.count(key)) fail(prefix + key, "unknown field");
    }
  }

 private:
  std::string source_;
};

std::string format_number(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

// Stages of profile_from_json, in the order of the file's fields.

// The file is a lucent-profile object of this version with no field we do not know.
void check_profile_format(const FieldReader& in, const json& doc, const std::string& source) {
  if (!doc.is_object()) throw Error(source + ": expected a JSON object (a lucent-profile file)");
  in.only_known(doc, "",
                {"format", "version", "calibrated", "units", "capture", "pixel_pitch_mm",
                 "incidence", "view_deg", "ior", "thickness_mm", "side", "system_response",
                 "beam_point_px",
                 "beam_point_source", "beam_power", "radial", "samples_2d", "masked",
                 "provenance"});
  if (!doc.contains("format") || doc["format"] != "lucent-profile") {
    in.fail("format", "expected \"lucent-profile\", found " +
                          (doc.contains("format") ? doc["format"].dump() : std::string("nothing")));
  }
  if (!doc.contains("version") || !doc["version"].is_number_integer() ||
      doc["version"].get<long long>() != Profile::kFormatVersion) {
    in.fail("version",
            "this lucent reads profile version 1, found " +
                (doc.contains("version") ? doc["version"].dump() : std::string("nothing")));
  }
}

// Whether the values are calibrated, the units that says they are in, and the capture file.
void read_calibration(const FieldReader& in, const json& doc, Profile& p) {
  const json& calibrated = in.get(doc, "calibrated", "calibrated");
  if (!calibrated.is_boolean()) in.fail("calibrated", "expected true or false");
  p.calibrated = calibrated.get<bool>();
  const json& units = in.get(doc, "units", "units");
  if (units != p.units()) {
    in.fail("units", "expected \"" + p.units() + "\" for a profile with calibrated " +
                         (p.calibrated ? "true" : "false") + ", found " + units.dump());
  }
  const json& capture = in.get(doc, "capture", "capture");
  if (!capture.is_string()) in.fail("capture", "expected a string (the capture file)");
  p.capture = capture.get<std::string>();
}

// The geometry: pixel pitch, incidence, view, relative index and slab.
void read_geometry(const FieldReader& in, const json& doc, const std::string& source, Profile& p) {
  p.pixel_pitch_mm = in.number(in.get(doc, "pixel_pitch_mm", "pixel_pitch_mm"), "pixel_pitch_mm");
  if (!(p.pixel_pitch_mm >= 1e-6 && p.pixel_pitch_mm <= 100))
    in.fail("pixel_pitch_mm", "expected a pixel pitch in [1e-6, 100] mm");
  const json& incidence = in.get(doc, "incidence", "incidence");
  if (!incidence.is_object()) in.fail("incidence", "expected {\"polar_deg\", \"azimuth_deg\"}");
  in.only_known(incidence, "incidence.", {"polar_deg", "azimuth_deg"});
  p.incidence_polar_deg =
      in.number(in.get(incidence, "polar_deg", "incidence.polar_deg"), "incidence.polar_deg");
  p.incidence_azimuth_deg =
      in.number(in.get(incidence, "azimuth_deg", "incidence.azimuth_deg"), "incidence.azimuth_deg");
  p.view_deg = in.number(in.get(doc, "view_deg", "view_deg"), "view_deg");
  if (doc.contains("ior")) {
    p.ior = in.number(doc["ior"], "ior");
    if (!(*p.ior >= 0.25 && *p.ior <= 4)) in.fail("ior", "expected a relative index in [0.25, 4]");
  }
  detail::read_slab_fields(doc, source, p.thickness_mm, p.transmitted);
}

// The optional system response `s` measured on the white reference.
void read_system_response(const FieldReader& in, const json& s, Profile& p) {
  if (!s.is_object()) in.fail("system_response", "expected an object");
  in.only_known(s, "system_response.", {"r_mm", "value", "rms_radius_mm", "units", "source"});
  const json& r = in.get(s, "r_mm", "system_response.r_mm");
  if (!r.is_array() || r.size() < 2 || r.size() > 100000)
    in.fail("system_response.r_mm", "expected 2..100000 radii");
  p.response_r_mm = in.numbers(r, "system_response.r_mm", r.size());
  p.response_value =
      in.numbers(in.get(s, "value", "system_response.value"), "system_response.value", r.size());
  p.response_rms_mm = in.number(in.get(s, "rms_radius_mm", "system_response.rms_radius_mm"),
                                "system_response.rms_radius_mm");
  for (std::size_t i = 0; i < p.response_r_mm.size(); ++i)
    if (!(p.response_r_mm[i] >= 0) || (i > 0 && !(p.response_r_mm[i] > p.response_r_mm[i - 1])))
      in.fail("system_response.r_mm", "expected radii >= 0 mm, rising");
  if (!(p.response_rms_mm >= 0)) in.fail("system_response.rms_radius_mm", "expected >= 0 mm");
}

// The beam: its entry point, how that was found, and its power (needed when calibrated).
void read_beam(const FieldReader& in, const json& doc, Profile& p) {
  const auto point = in.numbers(in.get(doc, "beam_point_px", "beam_point_px"), "beam_point_px", 2);
  p.beam_point_px = {point[0], point[1]};
  const json& point_source = in.get(doc, "beam_point_source", "beam_point_source");
  if (point_source != "detected" && point_source != "given") {
    in.fail("beam_point_source",
            "expected \"detected\" or \"given\", found " + point_source.dump());
  }
  p.beam_point_source = point_source.get<std::string>();
  const json& power = in.get(doc, "beam_power", "beam_power");
  if (!power.is_null()) {
    const auto values = in.numbers(power, "beam_power", 3);
    for (double v : values) {
      if (!(v >= 1e-30 && v <= 1e30))
        in.fail("beam_power", "expected three powers in [1e-30, 1e30] (R, G, B) or null");
    }
    p.beam_power = std::array<double, 3>{values[0], values[1], values[2]};
  }
  if (p.calibrated && !p.beam_power)
    in.fail("beam_power", "a calibrated profile needs the beam power");
}

// The radial profile: bins of equal length in every array, each with 0 <= r_inner < r_outer.
void read_radial(const FieldReader& in, const json& radial, RadialProfile& r) {
  if (!radial.is_object()) in.fail("radial", "expected an object");
  in.only_known(radial, "radial.",
                {"r_mm", "r_inner_mm", "r_outer_mm", "value", "standard_error", "count"});
  r.r_mm = in.numbers(in.get(radial, "r_mm", "radial.r_mm"), "radial.r_mm");
  const std::size_t bins = r.r_mm.size();
  r.r_inner_mm =
      in.numbers(in.get(radial, "r_inner_mm", "radial.r_inner_mm"), "radial.r_inner_mm", bins);
  r.r_outer_mm =
      in.numbers(in.get(radial, "r_outer_mm", "radial.r_outer_mm"), "radial.r_outer_mm", bins);
  r.value = in.channels(in.get(radial, "value", "radial.value"), "radial.value", bins, "r_mm");
  r.standard_error = in.channels(in.get(radial, "standard_error", "radial.standard_error"),
                                 "radial.standard_error", bins, "r_mm");
  const json& count = in.get(radial, "count", "radial.count");
  if (!count.is_array() || count.size() != 3)
    in.fail("radial.count", "expected 3 arrays (R, G, B)");
  for (int c = 0; c < 3; ++c) {
    r.count[c] = in.counts(count[c], "radial.count[" + std::to_string(c) + "]", bins);
  }
  for (std::size_t i = 0; i < bins; ++i) {
    if (!(r.r_inner_mm[i] >= 0 && r.r_inner_mm[i] < r.r_outer_mm[i])) {
      in.fail("radial.r_inner_mm[" + std::to_string(i) + "]", "expected 0 <= r_inner < r_outer");
    }
  }
}

// The optional 2D samples `s2`: one position and one value per channel per sample.
Samples2d read_samples_2d(const FieldReader& in, const json& s2) {
  if (!s2.is_object()) in.fail("samples_2d", "expected an object");
  in.only_known(s2, "samples_2d.", {"x_mm", "y_mm", "value", "standard_error"});
  Samples2d s;
  s.x_mm = in.numbers(in.get(s2, "x_mm", "samples_2d.x_mm"), "samples_2d.x_mm");
  s.y_mm = in.numbers(in.get(s2, "y_mm", "samples_2d.y_mm"), "samples_2d.y_mm", s.x_mm.size());
  s.value = in.channels(in.get(s2, "value", "samples_2d.value"), "samples_2d.value", s.x_mm.size(),
                        "sample");
  s.standard_error = in.channels(in.get(s2, "standard_error", "samples_2d.standard_error"),
                                 "samples_2d.standard_error", s.x_mm.size(), "sample");
  return s;
}

// The masked pixel counts per channel.
void read_masked(const FieldReader& in, const json& masked, MaskCounts& counts) {
  if (!masked.is_object()) in.fail("masked", "expected {\"saturated\", \"black\", \"non_finite\"}");
  in.only_known(masked, "masked.", {"saturated", "black", "non_finite"});
  const auto read_counts = [&](const char* key, std::array<std::int64_t, 3>& out) {
    const std::string field = std::string("masked.") + key;
    const auto values = in.counts(in.get(masked, key, field), field, 3);
    std::copy(values.begin(), values.end(), out.begin());
  };
  read_counts("saturated", counts.saturated);
  read_counts("black", counts.black);
  read_counts("non_finite", counts.non_finite);
}

}  // namespace

std::string Profile::units() const {
  return calibrated ? kCalibratedUnits : kRelativeUnits;
}

json profile_to_json(const Profile& profile) {
  return json::parse(profile_to_ordered_json(profile).dump());
}

Profile profile_from_json(const json& doc, const std::string& source) {
  const FieldReader in(source);
  check_profile_format(in, doc, source);
  Profile p;
  read_calibration(in, doc, p);
  read_geometry(in, doc, source, p);
  if (doc.contains("system_response")) read_system_response(in, doc["system_response"], p);
  read_beam(in, doc, p);
  read_radial(in, in.get(doc, "radial", "radial"), p.radial);
  if (doc.contains("samples_2d")) p.samples_2d = read_samples_2d(in, doc["samples_2d"]);
  read_masked(in, in.get(doc, "masked", "masked"), p.masked);
  if (doc.contains("provenance")) {
    if (!doc["provenance"].is_object()) in.fail("provenance", "expected an object");
    p.provenance = doc["provenance"];
  }
  return p;
}

Profile read_profile(const std::filesystem::path& path) {
  const std::string source = path.string();
  const json doc = read_json_file(path);
  return profile_from_json(doc, source);
}

void write_profile(const std::filesystem::path& path, const Profile& profile) {
  std::string text;
  const auto doc = profile_to_ordered_json(profile);
  check_finite_json(doc, path.string());
  dump_compact(doc, 0, text);
  write_file_atomically(path, text + "\n");
}

std::string profile_csv(const Profile& profile) {
  // The one radial CSV schema (lucent fit's reader, README "Radial CSV"): every comment token is
  // key=value; what the JSON says of the geometry and the calibration is said here too, so that a
  // fit of this file equals a fit of profile.json.
  std::string out = "# format=lucent-radial-csv version=1 source=lucent_acquire\n";
  out += "# quantity=radiance R_unit=";
  out += profile.calibrated ? "mm^-2_per_unit_incident_power" : "relative_per_unit_incident_power";
  out += " calibrated=";
  out += profile.calibrated ? "true" : "false";
  out += "\n";
  out += "# incidence_deg=" + format_number(profile.incidence_polar_deg) +
         " view_deg=" + format_number(profile.view_deg) +
         " pixel_mm=" + format_number(profile.pixel_pitch_mm);
  if (profile.ior) out += " ior=" + format_number(*profile.ior);
  if (profile.thickness_mm)
    out += " thickness_mm=" + format_number(*profile.thickness_mm) +
           " side=" + (profile.transmitted ? "transmitted" : "reflected");
  out += "\n";
  if (profile.beam_power && profile.provenance.contains("white_reference")) {
    const json& white = profile.provenance["white_reference"];
    if (white.is_object() && white.contains("beam_power_standard_error") &&
        white["beam_power_standard_error"].is_array() &&
        white["beam_power_standard_error"].size() == 3) {
      std::string se;
      for (int c = 0; c < 3; ++c) {
        const json& v = white["beam_power_standard_error"][c];
        const double power = (*profile.beam_power)[c];
        se += (c ? "," : "") +
              format_number(v.is_number() && power > 0 ? v.get<double>() / power : 0.0);
      }
      out += "# calibration_relative_se=" + se + "\n";
    }
  }
  if (!profile.response_r_mm.empty()) {
    // The white reference's system response (see Profile), as comma lists.
    std::string r = "# system_response_rms_mm=" + format_number(profile.response_rms_mm) +
                    "\n# system_response_r_mm=";
    for (std::size_t i = 0; i < profile.response_r_mm.size(); ++i)
      r += (i ? "," : "") + format_number(profile.response_r_mm[i]);
    r += "\n# system_response=";
    for (std::size_t i = 0; i < profile.response_value.size(); ++i)
      r += (i ? "," : "") + format_number(profile.response_value[i]);
    out += r + "\n";
  }
  out += "r_mm,r_inner_mm,r_outer_mm,R_r,R_g,R_b,se_r,se_g,se_b,n_r,n_g,n_b\n";
  const RadialProfile& r = profile.radial;
  for (std::size_t i = 0; i < r.size(); ++i) {
    out += format_number(r.r_mm[i]);
    out += "," + format_number(r.r_inner_mm[i]) + "," + format_number(r.r_outer_mm[i]);
    for (int c = 0; c < 3; ++c) out += "," + format_number(r.value[c][i]);
    for (int c = 0; c < 3; ++c) out += "," + format_number(r.standard_error[c][i]);
    for (int c = 0; c < 3; ++c) out += "," + std::to_string(r.count[c][i]);
    out += "\n";
  }
  return out;
}

std::vector<double> radial_bin_edges_mm(const RadialBinning& binning, double pixel_pitch_mm) {
  if (binning.bins < 1)
    throw Error("bins: expected at least 1, found " + std::to_string(binning.bins));
  if (!(binning.radius_mm > 0) || !std::isfinite(binning.radius_mm)) {
    throw Error("radius_mm: expected a radius > 0 mm, found " + format_number(binning.radius_mm));
  }
  if (!(pixel_pitch_mm > 0)) throw Error("pixel_pitch_mm: expected a pixel pitch > 0 mm");
  const int n = binning.bins;
  std::vector<double> edges(std::size_t(n) + 1, 0.0);
  if (!binning.log_bins || n == 1) {
    for (int i = 0; i <= n; ++i) edges[i] = binning.radius_mm * i / n;
    return edges;
  }
  const double first = pixel_pitch_mm / 2;
  if (!(binning.radius_mm > first)) {
    throw Error("radius_mm: " + format_number(binning.radius_mm) +
                " mm is not above half a pixel pitch (" + format_number(first) +
                " mm), too small for log-spaced bins");
  }
  for (int i = 1; i <= n; ++i) {
    edges[i] = first * std::pow(binning.radius_mm / first, double(i - 1) / (n - 1));
  }
  edges[n] = binning.radius_mm;  // exact, whatever pow rounds to
  return edges;
}

namespace {

// Standard error of a bin's mean from the scatter of its pixels about a straight line in r (n >= 3;
// the plain scatter for n = 2, 0 for one pixel). Centred sums keep the regression well conditioned.
double detrended_standard_error(const std::vector<std::pair<double, double>>& samples, double mean,
                                double m2) {
  const double n = double(samples.size());
  if (samples.size() < 2) return 0.0;
  if (samples.size() < 3) return std::sqrt(m2 / (n - 1) / n);
  double r_mean = 0;
  for (const auto& s : samples) r_mean += s.first;
  r_mean /= n;
  double srr = 0, srv = 0;
  for (const auto& [r, v] : samples) {
    srr += (r - r_mean) * (r - r_mean);
    srv += (r - r_mean) * (v - mean);
  }
  const double slope = srr > 0 ? srv / srr : 0.0;
  double ss = 0;
  for (const auto& [r, v] : samples) {
    const double e = v - mean - slope * (r - r_mean);
    ss += e * e;
  }
  return std::sqrt(ss / (n - 2) / n);
}

}  // namespace

RadialProfile bin_radial_profile(const HdrResult& hdr, const std::array<double, 2>& beam_point_px,
                                 double pixel_pitch_mm, const std::array<double, 3>& scale,
                                 const RadialBinning& binning) {
  const std::vector<double> edges = radial_bin_edges_mm(binning, pixel_pitch_mm);
  const std::size_t bins = edges.size() - 1;
  // Per bin and channel: the pixels' (r, value) for a scatter about the bin's own linear trend in r
  // (the profile falls across a bin; scatter about the plain mean would count that fall as noise
  // and overstate the error several times), and the propagated per-pixel errors.
  struct Accumulator {
    std::int64_t n = 0;
    double mean = 0, m2 = 0, se2 = 0;
    std::vector<std::pair<double, double>> samples;
  };
  std::vector<std::array<Accumulator, 3>> acc(bins);
  std::vector<std::int64_t> pixels(bins, 0);
  std::vector<double> sum_r(bins, 0.0);
  for (int y = 0; y < hdr.height(); ++y) {
    for (int x = 0; x < hdr.width(); ++x) {
      const double r =
          pixel_pitch_mm * std::hypot(x + 0.5 - beam_point_px[0], y + 0.5 - beam_point_px[1]);
      if (r > edges.back()) continue;
      const std::size_t bin = std::min<std::size_t>(
          std::upper_bound(edges.begin(), edges.end(), r) - edges.begin() - 1, bins - 1);
      bool any = false;
      for (int c = 0; c < 3; ++c) {
        if (!hdr.valid(x, y, c)) continue;
        any = true;
        Accumulator& a = acc[bin][c];
        const double value = scale[c] * hdr.radiance.at(x, y, c);
        const double se = scale[c] * hdr.standard_error.at(x, y, c);
        ++a.n;
        const double delta = value - a.mean;
        a.mean += delta / double(a.n);
        a.m2 += delta * (value - a.mean);
        a.se2 += se * se;
        a.samples.emplace_back(r, value);
      }
      if (any) ++pixels[bin], sum_r[bin] += r;
    }
  }
  RadialProfile out;
  const std::int64_t min_pixels = std::max(binning.min_pixels_per_bin, 1);
  for (std::size_t b = 0; b < bins; ++b) {
    bool enough = true;
    for (int c = 0; c < 3; ++c) enough = enough && acc[b][c].n >= min_pixels;
    if (!enough) continue;
    out.r_mm.push_back(sum_r[b] / double(pixels[b]));
    out.r_inner_mm.push_back(edges[b]);
    out.r_outer_mm.push_back(edges[b + 1]);
    for (int c = 0; c < 3; ++c) {
      const Accumulator& a = acc[b][c];
      const double n = double(a.n);
      const double spread = detrended_standard_error(a.samples, a.mean, a.m2);
      out.value[c].push_back(a.mean);
      out.standard_error[c].push_back(std::max(spread, std::sqrt(a.se2) / n));
      out.count[c].push_back(a.n);
    }
  }
  return out;
}

Samples2d sample_2d_profile(const HdrResult& hdr, const std::array<double, 2>& beam_point_px,
                            double pixel_pitch_mm, const std::array<double, 3>& scale,
                            double radius_mm) {
  Samples2d out;
  for (int y = 0; y < hdr.height(); ++y) {
    for (int x = 0; x < hdr.width(); ++x) {
      const double dx = pixel_pitch_mm * (x + 0.5 - beam_point_px[0]);
      const double dy = pixel_pitch_mm * (y + 0.5 - beam_point_px[1]);
      if (std::hypot(dx, dy) > radius_mm) continue;
      if (!hdr.valid(x, y, 0) || !hdr.valid(x, y, 1) || !hdr.valid(x, y, 2)) continue;
      out.x_mm.push_back(dx);
      out.y_mm.push_back(dy);
      for (int c = 0; c < 3; ++c) {
        out.value[c].push_back(scale[c] * hdr.radiance.at(x, y, c));
        out.standard_error[c].push_back(scale[c] * hdr.standard_error.at(x, y, c));
      }
    }
  }
  return out;
}

}  // namespace lucent::acquire
