#include "lucent/acquire/capture.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/imaging/camera_raw.h"
#include "slab_fields.h"

namespace lucent::acquire {
namespace {

using nlohmann::json;

class FieldReader {
 public:
  explicit FieldReader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw Error(source_ + ": field '" + field + "': " + what);
  }

  double number(const json& value, const std::string& field) const {
    if (!value.is_number()) fail(field, "expected a number, found " + describe(value));
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(field, "expected a finite number");
    return v;
  }

  std::string string(const json& value, const std::string& field) const {
    if (!value.is_string() || value.get<std::string>().empty()) {
      fail(field, "expected a non-empty string, found " + describe(value));
    }
    return value.get<std::string>();
  }

  const json& object(const json& value, const std::string& field) const {
    if (!value.is_object()) fail(field, "expected an object, found " + describe(value));
    return value;
  }

  void only_known(const json& object, const std::string& prefix,
                  const std::set<std::string>& known) const {
    for (const auto& [key, value] : object.items()) {
      if (!known.count(key)) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        fail(prefix + key, "unknown field (known: " + list + ")");
      }
    }
  }

  static std::string describe(const json& value) {
    if (value.is_null()) return "null";
    if (value.is_string()) return "a string";
    if (value.is_boolean()) return "a boolean";
    if (value.is_number()) return "a number";
    if (value.is_array()) return "an array";
    return "an object";
  }

 private:
  std::string source_;
};

ImageSet read_image_set(const json& doc, const std::string& prefix, const FieldReader& in) {
  ImageSet set;
  const bool has_images = doc.contains("images"), has_hdr = doc.contains("hdr");
  if (has_images == has_hdr) {
    in.fail(prefix + "images", "expected exactly one of '" + prefix + "images' (brackets) or '" +
                                   prefix + "hdr' (an OpenEXR file)");
  }
  if (has_hdr) {
    set.hdr = in.string(doc["hdr"], prefix + "hdr");
    return set;
  }
  const json& images = doc["images"];
  if (!images.is_array() || images.empty()) {
    in.fail(prefix + "images", "expected a non-empty array of {\"path\", \"exposure_s\"}");
  }
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string field = prefix + "images[" + std::to_string(i) + "]";
    const json& image = in.object(images[i], field);
    in.only_known(image, field + ".", {"path", "exposure_s", "iso"});
    if (!image.contains("path")) in.fail(field + ".path", "missing");
    Bracket b{in.string(image["path"], field + ".path")};
    // A camera RAW file knows its exposure time and ISO: the capture may leave them out.
    const bool raw = imaging::is_camera_raw_path(b.path);
    if (image.contains("exposure_s")) {
      b.exposure_s = in.number(image["exposure_s"], field + ".exposure_s");
      if (!(b.exposure_s >= 1e-9 && b.exposure_s <= 1e6))
        in.fail(field + ".exposure_s", "expected an exposure time in [1e-9, 1e6] s");
    } else if (!raw) {
      in.fail(field + ".exposure_s",
              "missing (only camera RAW files carry their exposure time in the file)");
    }
    if (image.contains("iso")) {
      b.iso = in.number(image["iso"], field + ".iso");
      if (!(*b.iso >= 1 && *b.iso <= 1e7)) in.fail(field + ".iso", "expected an ISO in [1, 1e7]");
    }
    // Known exposures must increase; those read from RAW files are ordered when they are read.
    if (b.exposure_s > 0 && !set.images.empty() && set.images.back().exposure_s > 0 &&
        !(b.exposure_s > set.images.back().exposure_s)) {
      in.fail(field + ".exposure_s",
              "exposures must increase strictly from one image to the next (got " +
                  std::to_string(b.exposure_s) + " s after " +
                  std::to_string(set.images.back().exposure_s) + " s)");
    }
    // One picture is one exposure: the same file at two exposure times is a slip of the pen
    // (merged, it would pass for a flat response).
    for (std::size_t k = 0; k < set.images.size(); ++k)
      if (set.images[k].path == b.path)
        in.fail(field + ".path", "'" + b.path.string() + "' is already image " + std::to_string(k) +
                                     ": each bracket is its own file");
    set.images.push_back(b);
  }
  return set;
}

json image_set_to_json(const ImageSet& set) {
  json doc = json::object();
  if (set.hdr) {
    doc["hdr"] = set.hdr->generic_string();
  } else {
    doc["images"] = json::array();
    for (const Bracket& b : set.images) {
      json image = {{"path", b.path.generic_string()}};
      if (b.exposure_s > 0) image["exposure_s"] = b.exposure_s;
      if (b.iso) image["iso"] = *b.iso;
      doc["images"].push_back(image);
    }
  }
  return doc;
}

}  // namespace

std::string to_string(Response response) {
  switch (response) {
    case Response::kLinear:
      return "linear";
    case Response::kSrgb:
      return "srgb";
    case Response::kCalibrate:
      return "calibrate";
  }
  return "linear";
}

Capture read_capture(const std::filesystem::path& path) {
  return capture_from_json(read_json_file(path), path.string(), path.parent_path());
}

Capture capture_from_json(const nlohmann::json& doc, const std::string& source,
                          const std::filesystem::path& base_dir) {
  const FieldReader in(source);
  if (!doc.is_object()) throw Error(source + ": expected a JSON object (a lucent-capture file)");
  in.only_known(
      doc, "",
      {"format", "version", "images", "hdr", "pixel_pitch_mm", "incidence", "view_deg", "ior",
       "thickness_mm", "side", "beam_point_px", "response", "dark", "white_reference", "beam_power", "provenance"});
  if (!doc.contains("format")) in.fail("format", "missing (expected \"lucent-capture\")");
  if (doc["format"] != "lucent-capture") {
    in.fail("format", "expected \"lucent-capture\", found " + doc["format"].dump());
  }
  if (!doc.contains("version") || !doc["version"].is_number_integer()) {
    in.fail("version", "expected the integer 1");
  }
  if (doc["version"].get<long long>() > Capture::kFormatVersion ||
      doc["version"].get<long long>() < 1) {
    in.fail("version", "this lucent reads capture version 1, found " + doc["version"].dump());
  }

  Capture c;
  c.base_dir = base_dir;
  c.sample = read_image_set(doc, "", in);
  if (!doc.contains("pixel_pitch_mm"))
    in.fail("pixel_pitch_mm", "missing (pixel size on the sample in mm)");
  c.pixel_pitch_mm = in.number(doc["pixel_pitch_mm"], "pixel_pitch_mm");
  // 1 nm to 100 mm per pixel: beyond either end the profile's areas under- or overflow.
  if (!(c.pixel_pitch_mm >= 1e-6 && c.pixel_pitch_mm <= 100))
    in.fail("pixel_pitch_mm", "expected a pixel pitch in [1e-6, 100] mm");

  if (!doc.contains("incidence"))
    in.fail("incidence", "missing (expected {\"polar_deg\", \"azimuth_deg\"})");
  const json& incidence = in.object(doc["incidence"], "incidence");
  in.only_known(incidence, "incidence.", {"polar_deg", "azimuth_deg"});
  if (!incidence.contains("polar_deg")) in.fail("incidence.polar_deg", "missing");
  c.incidence_polar_deg = in.number(incidence["polar_deg"], "incidence.polar_deg");
  if (!(c.incidence_polar_deg >= 0 && c.incidence_polar_deg < 90)) {
    in.fail("incidence.polar_deg", "expected an angle from the normal in [0, 90) degrees");
  }
  if (incidence.contains("azimuth_deg")) {
    c.incidence_azimuth_deg = in.number(incidence["azimuth_deg"], "incidence.azimuth_deg");
  }
  if (doc.contains("view_deg")) {
    c.view_deg = in.number(doc["view_deg"], "view_deg");
    if (!(c.view_deg >= 0 && c.view_deg < 90)) in.fail("view_deg", "expected [0, 90) degrees");
  }
  if (doc.contains("ior")) {
    c.ior = in.number(doc["ior"], "ior");
    if (!(*c.ior >= 0.25 && *c.ior <= 4)) in.fail("ior", "expected a relative index in [0.25, 4]");
  }
  detail::read_slab_fields(doc, source, c.thickness_mm, c.transmitted);
  if (doc.contains("beam_point_px")) {
    const json& p = doc["beam_point_px"];
    if (!p.is_array() || p.size() != 2) in.fail("beam_point_px", "expected [x, y] in pixels");
    c.beam_point_px = std::array<double, 2>{in.number(p[0], "beam_point_px[0]"),
                                            in.number(p[1], "beam_point_px[1]")};
    if (!(std::abs((*c.beam_point_px)[0]) <= 1e6 && std::abs((*c.beam_point_px)[1]) <= 1e6))
      in.fail("beam_point_px", "expected pixel coordinates within 1e6 of the image");
  }
  if (doc.contains("response")) {
    const std::string r = in.string(doc["response"], "response");
    if (r == "linear")
      c.response = Response::kLinear;
    else if (r == "srgb")
      c.response = Response::kSrgb;
    else if (r == "calibrate")
      c.response = Response::kCalibrate;
    else
      in.fail("response", "expected \"linear\", \"srgb\" or \"calibrate\", found \"" + r + "\"");
  }
  if (doc.contains("dark")) c.dark = in.string(doc["dark"], "dark");
  if (doc.contains("white_reference")) {
    const json& w = in.object(doc["white_reference"], "white_reference");
    in.only_known(w, "white_reference.", {"images", "hdr", "reflectance"});
    WhiteReference white;
    white.images = read_image_set(w, "white_reference.", in);
    if (!w.contains("reflectance")) in.fail("white_reference.reflectance", "missing (e.g. 0.99)");
    white.reflectance = in.number(w["reflectance"], "white_reference.reflectance");
    if (!(white.reflectance > 0 && white.reflectance <= 1)) {
      in.fail("white_reference.reflectance", "expected a reflectance in (0, 1]");
    }
    c.white_reference = white;
  }
  if (doc.contains("beam_power")) {
    c.beam_power = in.number(doc["beam_power"], "beam_power");
    // Any unit (W, or the camera's own), but a number whose inverse is a number: radiance is
    // divided by it.
    if (!(*c.beam_power >= 1e-30 && *c.beam_power <= 1e30))
      in.fail("beam_power", "expected a power in [1e-30, 1e30] (in the unit the profile is per)");
  }
  if (doc.contains("provenance")) c.provenance = doc["provenance"];
  return c;
}

json capture_to_json(const Capture& c) {
  json doc = json::object();
  doc["format"] = "lucent-capture";
  doc["version"] = Capture::kFormatVersion;
  const json set = image_set_to_json(c.sample);
  for (const auto& [key, value] : set.items()) doc[key] = value;
  doc["pixel_pitch_mm"] = c.pixel_pitch_mm;
  doc["incidence"] = {{"polar_deg", c.incidence_polar_deg},
                      {"azimuth_deg", c.incidence_azimuth_deg}};
  doc["view_deg"] = c.view_deg;
  if (c.ior) doc["ior"] = *c.ior;
  if (c.thickness_mm) doc["thickness_mm"] = *c.thickness_mm;
  if (c.thickness_mm) doc["side"] = c.transmitted ? "transmitted" : "reflected";
  if (c.beam_point_px) doc["beam_point_px"] = {(*c.beam_point_px)[0], (*c.beam_point_px)[1]};
  doc["response"] = to_string(c.response);
  if (c.dark) doc["dark"] = c.dark->generic_string();
  if (c.white_reference) {
    json w = image_set_to_json(c.white_reference->images);
    w["reflectance"] = c.white_reference->reflectance;
    doc["white_reference"] = w;
  }
  if (c.beam_power) doc["beam_power"] = *c.beam_power;
  if (!c.provenance.is_null()) doc["provenance"] = c.provenance;
  return doc;
}

void write_capture(const std::filesystem::path& path, const Capture& capture) {
  // Keep "format" and "version" first for a person opening the file.
  const json doc = capture_to_json(capture);
  check_finite_json(doc, path.string());
  std::ostringstream out;
  out << "{\n  \"format\": \"lucent-capture\",\n  \"version\": " << Capture::kFormatVersion;
  for (const auto& [key, value] : doc.items()) {
    if (key == "format" || key == "version") continue;
    std::string text = value.dump(2);
    std::string indented;
    for (char ch : text) {
      indented += ch;
      if (ch == '\n') indented += "  ";
    }
    out << ",\n  \"" << key << "\": " << indented;
  }
  out << "\n}\n";
  write_file_atomically(path, out.str());
}

}  // namespace lucent::acquire
