// The material file ("format": "lucent-material", "version": 1; docs/DESIGN.md §3) and the bundled
// library. The reader accepts exactly the documented fields and rejects everything else with one
// line naming the file, the field, what was expected and what was found (STYLE 4).
#include "lucent/materials/material.h"
#include "lucent/core/json_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string_view>
#include <system_error>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/materials/albedo.h"
#include "lucent/materials/dipole.h"

namespace lucent::materials {
namespace {

using nlohmann::json;

constexpr std::string_view kFormatName = "lucent-material";
constexpr std::array<std::string_view, 3> kChannelNames = {"R", "G", "B"};

// Every top-level field the format knows, in the order they are written.
constexpr std::array<std::string_view, 16> kKnownFields = {
    "format",         "version",        "name",        "ior",        "sigma_a",
    "sigma_s_reduced", "sigma_s",       "g",           "model",      "adequate_model",
    "fallback_model", "uncertainty",    "provenance",  "derived",    "diffuse_colour",
    "mfp_mm"};

// Agreement required between a given sigma_s' and sigma_s (1 - g): relative, with an absolute floor
// for channels that (almost) do not scatter, where a relative test would demand exact zeros.
constexpr double kMaxCoefficient = 1e6;  // mm^-1
constexpr double kReducedRelativeTolerance = 1e-6;
constexpr double kReducedAbsoluteTolerance = 1e-12;

// An error message is the single line the CLI prints; keys and parser messages from a hostile file
// could otherwise carry line breaks into it.
std::string one_line(std::string s) {
  std::replace_if(
      s.begin(), s.end(), [](char ch) { return ch == '\n' || ch == '\r'; }, ' ');
  return s;
}

// Shortest text that reads back as the same double; spelled out for NaN and infinities, which
// json::dump() would print as null.
std::string format_number(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return json(x).dump();
}

std::string truncated(std::string s) {
  constexpr std::size_t kMax = 60;
  if (s.size() > kMax) s = s.substr(0, kMax) + "...";
  return s;
}

// What the reader found, for the "found ..." half of a message.
std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return "boolean " + v.dump();
    case json::value_t::string:
      return "string " + truncated(v.dump());
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return v.dump();
    case json::value_t::number_float:
      return format_number(v.get<double>());
    case json::value_t::array:
      return "an array of " + std::to_string(v.size()) + (v.size() == 1 ? " element" : " elements");
    case json::value_t::object:
      return "an object";
    default:
      return v.type_name();
  }
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string join(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += separator;
    out += items[i];
  }
  return out;
}

// Reads one document; every failure goes through fail() so all messages share one shape.
class MaterialReader {
 public:
  MaterialReader(const json& doc, const std::string& source) : doc_(doc), source_(source) {}

  Material read() {
    if (!doc_.is_object()) {
      throw Error(one_line(source_ + ": expected a JSON object with \"format\": \"" +
                           std::string(kFormatName) + "\", found " + describe(doc_)));
    }
    // Format and version first: a file of another kind should be reported as such, not as a
    // material with unknown fields.
    check_format();
    check_version();
    check_known_fields();

    Material m;
    m.name = read_name();
    m.ior = read_ior();
    if (find("diffuse_colour") || find("mfp_mm")) {
      read_appearance(m);
      return finish(m);
    }
    m.sigma_a = read_rgb("sigma_a", "a number in [0, 1e6] (mm^-1)", is_coefficient);

    const json* sigma_s = find("sigma_s");
    const json* g = find("g");
    if (sigma_s && !g) fail("g", "missing; expected together with 'sigma_s' (both or neither)");
    if (g && !sigma_s) fail("sigma_s", "missing; expected together with 'g' (both or neither)");
    if (sigma_s) {
      m.sigma_s = read_rgb("sigma_s", "a number in [0, 1e6] (mm^-1)", is_coefficient);
      m.g = read_rgb("g", "a number in (-1, 1)", is_mean_cosine);
    }

    if (find("sigma_s_reduced")) {
      m.sigma_s_reduced =
          read_rgb("sigma_s_reduced", "a number in [0, 1e6] (mm^-1)", is_coefficient);
      if (m.sigma_s) check_reduced_agrees(m);
    } else if (m.sigma_s) {
      for (int c = 0; c < 3; ++c) m.sigma_s_reduced[c] = (*m.sigma_s)[c] * (1.0 - (*m.g)[c]);
    } else {
      fail("sigma_s_reduced",
           "missing; expected an array of 3 numbers in [0, 1e6] (mm^-1), or 'sigma_s' with 'g', "
           "or 'diffuse_colour' with 'mfp_mm'");
    }
    return finish(m);
  }

 private:
  // The fields after the coefficients, whichever way these were given.
  Material finish(Material& m) {
    if (const json* model = find("model")) {
      if (!model->is_string()) fail("model", "expected a string, found " + describe(*model));
      m.model = model->get<std::string>();
      if (m.model != "dipole" && m.model != "ddipole" && m.model != "tabulated")
        fail("model", "expected \"dipole\", \"ddipole\" or \"tabulated\", found \"" +
                          truncated(m.model) + "\"");
    }
    if (const json* adequate = find("adequate_model")) {
      if (!adequate->is_string() || (*adequate != "dipole" && *adequate != "ddipole" &&
                                     *adequate != "tabulated" && *adequate != "none"))
        fail("adequate_model", "expected \"dipole\", \"ddipole\", \"tabulated\" or \"none\", found " +
                                   describe(*adequate));
      m.adequate_model = adequate->get<std::string>();
    }
    if (const json* fallback = find("fallback_model")) {
      if (!fallback->is_string() || (*fallback != "dipole" && *fallback != "ddipole"))
        fail("fallback_model", "expected \"dipole\" or \"ddipole\", found " + describe(*fallback));
      m.fallback_model = fallback->get<std::string>();
    }
    m.uncertainty = read_object_or_null("uncertainty");
    m.provenance = read_object_or_null("provenance");
    // "derived" is written for people and other tools; it is recomputed, never trusted.
    return m;
  }

  // An appearance instead of coefficients (pbrt's reflectance/mfp, Blender's colour and radius):
  // per channel the standard dipole's total diffuse reflectance in (0, 1) and the diffuse mean
  // free path 1 / sigma_tr in mm, inverted by coefficients_from_diffuse_colour (Jensen and Buhler
  // 2002) at the material's index.
  void read_appearance(Material& m) {
    for (std::string_view other : {"sigma_a", "sigma_s_reduced", "sigma_s", "g"})
      if (find(other))
        fail(other, "given with 'diffuse_colour'/'mfp_mm': give coefficients or an appearance, "
                    "not both");
    if (!find("diffuse_colour")) fail("diffuse_colour", "missing; expected together with 'mfp_mm'");
    if (!find("mfp_mm")) fail("mfp_mm", "missing; expected together with 'diffuse_colour'");
    const Rgb colour = read_rgb("diffuse_colour", "a total diffuse reflectance in (0, 1)",
                                [](double x) { return std::isfinite(x) && x > 0 && x < 1; });
    const Rgb mfp = read_rgb("mfp_mm", "a diffuse mean free path in (0, 1e6] mm",
                             [](double x) { return std::isfinite(x) && x > 0 && x <= 1e6; });
    for (int c = 0; c < 3; ++c) {
      const ReducedCoefficients k = coefficients_from_diffuse_colour(colour[c], mfp[c], m.ior);
      if (!(is_coefficient(k.sigma_a) && is_coefficient(k.sigma_s_reduced)))
        fail("mfp_mm", "element " + std::to_string(c) + " gives coefficients beyond 1e6 mm^-1");
      m.sigma_a[c] = k.sigma_a;
      m.sigma_s_reduced[c] = k.sigma_s_reduced;
    }
  }

  // At most 1e6 mm^-1 (a mean free path of a nanometre): beyond it the models' exponentials and
  // products overflow and no optical measurement could tell the difference.
  static bool is_coefficient(double x) {
    return std::isfinite(x) && x >= 0.0 && x <= kMaxCoefficient;
  }
  static bool is_mean_cosine(double x) { return std::isfinite(x) && x > -1.0 && x < 1.0; }

  [[noreturn]] void fail(std::string_view field, const std::string& what) const {
    throw Error(one_line(source_ + ": field '" + std::string(field) + "': " + what));
  }

  const json* find(std::string_view field) const {
    const auto it = doc_.find(field);
    return it == doc_.end() ? nullptr : &*it;
  }

  void check_format() const {
    const std::string expected = "\"" + std::string(kFormatName) + "\"";
    const json* format = find("format");
    if (!format) fail("format", "missing; expected " + expected);
    if (!format->is_string() || format->get<std::string>() != kFormatName) {
      fail("format", "expected " + expected + " (a material file), found " + describe(*format));
    }
  }

  void check_version() const {
    const json* version = find("version");
    const std::string supported = std::to_string(Material::kFormatVersion);
    if (!version) fail("version", "missing; expected a positive integer <= " + supported);
    bool positive = false;
    bool newer = false;
    if (version->is_number_unsigned()) {
      const auto v = version->get<std::uint64_t>();
      positive = v >= 1;
      newer = v > static_cast<std::uint64_t>(Material::kFormatVersion);
    } else if (version->is_number_integer()) {
      const auto v = version->get<std::int64_t>();
      positive = v >= 1;
      newer = v > Material::kFormatVersion;
    }
    if (!positive) fail("version", "expected a positive integer, found " + describe(*version));
    if (newer) {
      fail("version", "expected " + supported + " or older (this reader's version), found " +
                          describe(*version) + ": the file was written by a newer lucent");
    }
  }

  void check_known_fields() const {
    for (const auto& item : doc_.items()) {
      const std::string& key = item.key();
      if (std::find(kKnownFields.begin(), kKnownFields.end(), key) != kKnownFields.end()) continue;
      std::string what = "unknown field";
      std::size_t best = 3;  // suggest only names within two edits: typos, not guesses
      std::string_view suggestion;
      for (std::string_view known : kKnownFields) {
        const std::size_t d = edit_distance(key, known);
        if (d < best) best = d, suggestion = known;
      }
      if (!suggestion.empty()) what += " (did you mean '" + std::string(suggestion) + "'?)";
      std::vector<std::string> known;
      for (std::string_view k : kKnownFields) known.emplace_back(k);
      fail(truncated(key), what + "; expected only " + join(known, ", "));
    }
  }

  std::string read_name() const {
    const json* name = find("name");
    if (!name) fail("name", "missing; expected a non-empty string");
    if (!name->is_string() || name->get<std::string>().empty()) {
      fail("name", "expected a non-empty string, found " + describe(*name));
    }
    return name->get<std::string>();
  }

  double read_ior() const {
    const std::string expected = "a number in [0.25, 4] (n_sample / n_outside)";
    const json* ior = find("ior");
    if (!ior) fail("ior", "missing; expected " + expected);
    if (!ior->is_number()) fail("ior", "expected " + expected + ", found " + describe(*ior));
    const double x = ior->get<double>();
    if (!(std::isfinite(x) && x >= 0.25 && x <= 4.0)) {
      fail("ior", "expected " + expected + ", found " + describe(*ior));
    }
    return x;
  }

  Rgb read_rgb(std::string_view field, const std::string& element,
               const std::function<bool(double)>& valid) const {
    const std::string expected = "an array of 3 numbers (R, G, B), each " + element;
    const json* v = find(field);
    if (!v) fail(field, "missing; expected " + expected);
    if (!v->is_array() || v->size() != 3)
      fail(field, "expected " + expected + ", found " + describe(*v));
    Rgb out{};
    for (std::size_t c = 0; c < 3; ++c) {
      const json& x = (*v)[c];
      const std::string where = "element " + std::to_string(c) + " (" +
                                std::string(kChannelNames[c]) + "): expected " + element;
      if (!x.is_number()) fail(field, where + ", found " + describe(x));
      out[c] = x.get<double>();
      if (!valid(out[c])) fail(field, where + ", found " + describe(x));
    }
    return out;
  }

  void check_reduced_agrees(const Material& m) const {
    for (std::size_t c = 0; c < 3; ++c) {
      const double computed = (*m.sigma_s)[c] * (1.0 - (*m.g)[c]);
      const double given = m.sigma_s_reduced[c];
      const double tolerance =
          std::max(kReducedRelativeTolerance * std::max(std::abs(computed), std::abs(given)),
                   kReducedAbsoluteTolerance);
      if (std::abs(given - computed) > tolerance) {
        fail("sigma_s_reduced", "element " + std::to_string(c) + " (" +
                                    std::string(kChannelNames[c]) +
                                    "): expected sigma_s (1 - g) = " + format_number(computed) +
                                    " (to 1e-6 relative), found " + format_number(given));
      }
    }
  }

  json read_object_or_null(std::string_view field) const {
    const json* v = find(field);
    if (!v || v->is_null()) return nullptr;
    if (!v->is_object()) fail(field, "expected an object, found " + describe(*v));
    return *v;
  }

  const json& doc_;
  const std::string& source_;
};

json rgb_json(const Rgb& v) {
  return json::array({v[0], v[1], v[2]});
}

// NaN and infinities are not JSON (nlohmann would write null without saying so); make it explicit.
json finite_or_null(double x) {
  return std::isfinite(x) ? json(x) : json(nullptr);
}

std::string rgb_string(const Rgb& v) {
  std::ostringstream s;
  s.precision(6);
  s << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
  return s.str();
}

std::filesystem::path executable_relative_library() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return std::filesystem::path("share") / "lucent" / "materials";
  return (exe.parent_path() / ".." / "share" / "lucent" / "materials").lexically_normal();
}

}  // namespace

Medium<double> Material::medium(int channel) const {
  const auto c = static_cast<std::size_t>(channel);
  if (sigma_s && g) return Medium<double>{sigma_a.at(c), sigma_s->at(c), g->at(c), ior};
  return Medium<double>::from_reduced(sigma_a.at(c), sigma_s_reduced.at(c), ior);
}

std::string Material::to_string() const {
  std::ostringstream s;
  s.precision(6);
  s << "Material{name=" << name << ", ior=" << ior << ", sigma_a=" << rgb_string(sigma_a)
    << "/mm, sigma_s'=" << rgb_string(sigma_s_reduced) << "/mm";
  if (sigma_s) s << ", sigma_s=" << rgb_string(*sigma_s) << "/mm";
  if (g) s << ", g=" << rgb_string(*g);
  if (!model.empty()) s << ", model=" << model;
  s << "}";
  return s.str();
}

Material material_from_json(const nlohmann::json& doc, const std::string& source) {
  try {
    return MaterialReader(doc, source).read();
  } catch (const nlohmann::json::exception& e) {
    // The reader checks types before converting, so this is a guard, not an expected path.
    throw Error(one_line(source + ": " + e.what()));
  }
}

std::string Material::diffusion_model(const std::string& fallback) const {
  if (model == "dipole" || model == "ddipole" || model == "tabulated") return model;
  return fallback;
}

nlohmann::json material_to_json(const Material& material) {
  json doc;
  doc["format"] = kFormatName;
  doc["version"] = Material::kFormatVersion;
  doc["name"] = material.name;
  doc["ior"] = material.ior;
  doc["sigma_a"] = rgb_json(material.sigma_a);
  doc["sigma_s_reduced"] = rgb_json(material.sigma_s_reduced);
  if (material.sigma_s) doc["sigma_s"] = rgb_json(*material.sigma_s);
  if (material.g) doc["g"] = rgb_json(*material.g);
  if (!material.model.empty()) doc["model"] = material.model;
  if (!material.adequate_model.empty()) doc["adequate_model"] = material.adequate_model;
  if (!material.fallback_model.empty()) doc["fallback_model"] = material.fallback_model;
  if (!material.uncertainty.is_null()) doc["uncertainty"] = material.uncertainty;
  if (!material.provenance.is_null()) doc["provenance"] = material.provenance;

  json alpha_prime = json::array();
  json sigma_tr = json::array();
  json mean_free_path = json::array();
  json total_reflectance = json::array();
  for (int c = 0; c < 3; ++c) {
    const StandardDipole<double> dipole(material.medium(c));
    const DiffusionCoefficients<double>& k = dipole.coefficients();
    alpha_prime.push_back(finite_or_null(k.alpha_prime));
    sigma_tr.push_back(finite_or_null(k.sigma_tr));
    // A channel that does not absorb has no diffuse mean free path (light diffuses forever).
    mean_free_path.push_back(k.sigma_tr > 0.0 ? finite_or_null(1.0 / k.sigma_tr) : json(nullptr));
    total_reflectance.push_back(finite_or_null(dipole.total_diffuse_reflectance()));
  }
  doc["derived"] = {{"alpha_prime", alpha_prime},
                    {"sigma_tr_per_mm", sigma_tr},
                    {"diffuse_mean_free_path_mm", mean_free_path},
                    {"total_diffuse_reflectance", total_reflectance}};
  return doc;
}

}  // namespace lucent::materials


namespace lucent::materials {

Material read_material(const std::filesystem::path& path) {
  return material_from_json(read_json_file(path), path.string());
}

void write_material(const std::filesystem::path& path, const Material& material) {
  const json doc = material_to_json(material);
  // nlohmann::json sorts keys; files describe themselves from the first line (STYLE 4), so the
  // top level is written in the format's own order, "format" and "version" first.
  nlohmann::ordered_json ordered;
  for (std::string_view field : kKnownFields) {
    const auto it = doc.find(field);
    if (it != doc.end()) ordered[std::string(field)] = nlohmann::ordered_json(*it);
  }
  check_finite_json(ordered, path.string());
  // What lucent writes it must be able to read back: the reader's own ranges hold on every output
  // (a fit of profile values of 1e-320 wrote sigma_a = 2e46 mm^-1, past the reader's 1e6).
  try {
    (void)material_from_json(doc, path.string());
  } catch (const Error& e) {
    throw Error(path.string() + ": cannot write: the material would not read back (" +
                std::string(e.what()) + ")");
  }
  write_file_atomically(path, ordered.dump(2) + "\n");
}

std::filesystem::path material_library_dir() {
  if (const char* env = std::getenv("LUCENT_MATERIAL_LIBRARY"); env && *env) {
    return std::filesystem::path(env);
  }
#ifdef LUCENT_MATERIAL_LIBRARY_DIR
  {
    const std::filesystem::path source_tree(LUCENT_MATERIAL_LIBRARY_DIR);
    std::error_code ec;
    if (!source_tree.empty() && std::filesystem::is_directory(source_tree, ec)) return source_tree;
  }
#endif
  return executable_relative_library();
}

std::vector<std::string> library_material_names() {
  std::vector<std::string> names;
  std::error_code ec;
  std::filesystem::directory_iterator it(material_library_dir(), ec);
  if (ec) return names;  // no library: no names; load_material says where it looked
  for (const auto& entry : it) {
    const std::filesystem::path& p = entry.path();
    const std::string stem = p.stem().string();
    // Leading '.': hidden files and the temporaries of an interrupted write_material.
    if (p.extension() != ".json" || stem.empty() || stem[0] == '.') continue;
    if (!entry.is_regular_file(ec)) continue;
    names.push_back(stem);
  }
  std::sort(names.begin(), names.end());
  return names;
}

Material load_material(const std::string& name_or_path) {
  std::error_code ec;
  const std::filesystem::path as_path(name_or_path);
  const bool looks_like_path = name_or_path.find('/') != std::string::npos ||
                               as_path.extension() == ".json" ||
                               std::filesystem::is_regular_file(as_path, ec);
  if (looks_like_path) return read_material(as_path);

  const std::filesystem::path library = material_library_dir();
  const std::filesystem::path bundled = library / (name_or_path + ".json");
  if (std::filesystem::is_regular_file(bundled, ec)) return read_material(bundled);

  const std::vector<std::string> names = library_material_names();
  const std::string known =
      names.empty() ? "no bundled materials found in " + library.string() : join(names, ", ");
  throw Error(one_line("unknown material '" + name_or_path +
                       "': not a file, and not one of the bundled materials (" + known + ")"));
}

}  // namespace lucent::materials
