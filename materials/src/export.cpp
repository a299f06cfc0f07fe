// A material in other renderers' parameterisations (export.h).
#include "lucent/materials/export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "lucent/core/error.h"
#include "lucent/core/xml_text.h"
#include "lucent/materials/albedo.h"
#include "lucent/materials/dipole.h"

namespace lucent::materials {
namespace {

// Nine significant digits: what every format reads back within 1e-9 relative.
std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}
double reread(double v) {
  return std::stod(num(v));
}

std::string triple(const Rgb& v, const char* separator) {
  return num(v[0]) + separator + num(v[1]) + separator + num(v[2]);
}

// XML attribute and element text: names may hold anything a material file's name does.
// A MaterialX node name: letters, digits and underscores.
std::string mtlx_name(const std::string& s) {
  std::string out;
  for (char ch : s) out += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "M_" + out;
  return out;
}
// A pbrt string literal holds no quote or newline.
std::string pbrt_string(const std::string& s) {
  std::string out;
  // pbrt's strings end at '"' and take '\\' as an escape: neither, nor a control character, in a
  // name (a name ending in '\\' escaped the closing quote).
  for (char ch : s)
    out += (ch == '"' || ch == '\\' || static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ? '_' : ch;
  return out;
}

// What every target starts from, per channel.
struct Channels {
  Rgb g{}, sigma_a{}, sigma_s{}, sigma_t{};
  double g_mean = 0;
  bool g_differs = false;
};

Channels channels_of(const Material& m) {
  Channels c;
  for (int i = 0; i < 3; ++i) {
    c.g[i] = m.g ? (*m.g)[i] : 0.0;
    c.sigma_a[i] = m.sigma_a[i];
    c.sigma_s[i] = m.sigma_s ? (*m.sigma_s)[i] : m.sigma_s_reduced[i] / (1 - c.g[i]);
    c.sigma_t[i] = c.sigma_a[i] + c.sigma_s[i];
  }
  c.g_mean = (c.g[0] + c.g[1] + c.g[2]) / 3;
  c.g_differs = std::max({c.g[0], c.g[1], c.g[2]}) - std::min({c.g[0], c.g[1], c.g[2]}) > 1e-9;
  return c;
}

// The artist-facing pair: the standard dipole's total diffuse reflectance and the diffuse mean
// free path 1 / sigma_tr (mm), per channel.
struct Appearance {
  Rgb colour{}, mfp_mm{};
};

Appearance appearance_of(const Material& m, ExportTarget t) {
  Appearance a;
  static const char* names[3] = {"R", "G", "B"};
  for (int i = 0; i < 3; ++i) {
    const StandardDipole<double> dipole(m.medium(i));
    const double sigma_tr = dipole.coefficients().sigma_tr;
    a.colour[i] = dipole.total_diffuse_reflectance();
    if (!(sigma_tr > 0) || !(a.colour[i] > 0 && a.colour[i] < 1))
      throw Error(std::string("--to ") + to_string(t) + ": channel " + names[i] + " of '" + m.name +
                  "' has no diffuse colour and radius (it does not scatter, or does not absorb); " +
                  "export it to pbrt or mitsuba, which take the coefficients");
    a.mfp_mm[i] = 1 / sigma_tr;
  }
  return a;
}

void add_g_loss(const Channels& c, ExportResult& r) {
  if (c.g_differs)
    r.losses.push_back("one Henyey-Greenstein g for all channels: " + triple(c.g, ", ") +
                       " becomes their mean " + num(c.g_mean) +
                       " (sigma_s is kept, so sigma_s' moves: see the round trip)");
}

// Round trip of the appearance targets: lucent's inversion of what was written.
void invert_appearance(const Rgb& colour, const Rgb& mfp_mm, double eta, ExportResult& r) {
  for (int i = 0; i < 3; ++i) {
    const ReducedCoefficients k = coefficients_from_diffuse_colour(colour[i], mfp_mm[i], eta);
    r.sigma_a_back[i] = k.sigma_a;
    r.sigma_s_reduced_back[i] = k.sigma_s_reduced;
  }
}

ExportResult to_pbrt(const Material& m, double mm_per_unit) {
  const Channels c = channels_of(m);
  ExportResult r;
  const std::string name = pbrt_string(m.name);
  std::ostringstream s;
  s << "# lucent export of '" << name << "' for pbrt-v4. Coefficients are lucent's (mm^-1);\n"
    << "# \"scale\" " << num(mm_per_unit) << " makes them per scene unit (" << num(mm_per_unit)
    << " mm). sigma_s = sigma_s' / (1 - g).\n"
    << "MakeNamedMaterial \"" << name << "\"\n"
    << "    \"string type\" [ \"subsurface\" ]\n"
    << "    \"rgb sigma_a\" [ " << triple(c.sigma_a, " ") << " ]\n"
    << "    \"rgb sigma_s\" [ " << triple(c.sigma_s, " ") << " ]\n"
    << "    \"float g\" [ " << num(c.g_mean) << " ]\n"
    << "    \"float eta\" [ " << num(m.ior) << " ]\n"
    << "    \"float scale\" [ " << num(mm_per_unit) << " ]\n"
    << "# The same medium for volumetric path tracing (inside a dielectric interface):\n"
    << "MakeNamedMedium \"" << name << "_medium\"\n"
    << "    \"string type\" [ \"homogeneous\" ]\n"
    << "    \"rgb sigma_a\" [ " << triple(c.sigma_a, " ") << " ]\n"
    << "    \"rgb sigma_s\" [ " << triple(c.sigma_s, " ") << " ]\n"
    << "    \"float g\" [ " << num(c.g_mean) << " ]\n"
    << "    \"float scale\" [ " << num(mm_per_unit) << " ]\n";
  r.text = s.str();
  add_g_loss(c, r);
  r.losses.push_back(
      "pbrt's subsurface material renders with its own tabulated photon beam "
      "diffusion BSSRDF, not lucent's model (the medium form is exact transport)");
  for (int i = 0; i < 3; ++i) {
    r.sigma_a_back[i] = reread(c.sigma_a[i]);
    r.sigma_s_reduced_back[i] = reread(c.sigma_s[i]) * (1 - reread(c.g_mean));
  }
  return r;
}

ExportResult to_mitsuba(const Material& m, double mm_per_unit) {
  const Channels c = channels_of(m);
  ExportResult r;
  Rgb albedo{};
  for (int i = 0; i < 3; ++i) albedo[i] = c.sigma_t[i] > 0 ? c.sigma_s[i] / c.sigma_t[i] : 0;
  const std::string id = xml_escape(mtlx_name(m.name));
  const double radius = 10.0 / mm_per_unit;  // a 1 cm sphere
  std::ostringstream s;
  s << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
    << "<!-- lucent export of '" << xml_comment(m.name) << "' for Mitsuba 3: a homogeneous medium "
    << "inside a smooth dielectric, on a sphere of 1 cm (radius " << num(radius)
    << " scene units); sigma_t is lucent's (mm^-1), scale " << num(mm_per_unit)
    << " makes it per scene unit. -->\n"
    << "<scene version=\"3.0.0\">\n"
    << "  <integrator type=\"volpath\"><integer name=\"max_depth\" value=\"-1\"/></integrator>\n"
    << "  <sensor type=\"perspective\">\n"
    << "    <transform name=\"to_world\"><lookat origin=\"0, 0, " << num(5 * radius)
    << "\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>\n"
    << "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"256\"/>"
    << "<integer name=\"height\" value=\"256\"/></film>\n"
    << "    <sampler type=\"independent\"><integer name=\"sample_count\" "
       "value=\"256\"/></sampler>\n"
    << "  </sensor>\n"
    << "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"1\"/></emitter>\n"
    << "  <bsdf type=\"dielectric\" id=\"" << id << "_interface\">\n"
    << "    <float name=\"int_ior\" value=\"" << num(m.ior) << "\"/>\n"
    << "    <float name=\"ext_ior\" value=\"1\"/>\n"
    << "  </bsdf>\n"
    << "  <medium type=\"homogeneous\" id=\"" << id << "\">\n"
    << "    <rgb name=\"albedo\" value=\"" << triple(albedo, ", ") << "\"/>\n"
    << "    <rgb name=\"sigma_t\" value=\"" << triple(c.sigma_t, ", ") << "\"/>\n"
    << "    <float name=\"scale\" value=\"" << num(mm_per_unit) << "\"/>\n"
    << "    <phase type=\"hg\"><float name=\"g\" value=\"" << num(c.g_mean) << "\"/></phase>\n"
    << "  </medium>\n"
    << "  <shape type=\"sphere\">\n"
    << "    <float name=\"radius\" value=\"" << num(radius) << "\"/>\n"
    << "    <ref id=\"" << id << "_interface\"/>\n"
    << "    <ref name=\"interior\" id=\"" << id << "\"/>\n"
    << "  </shape>\n"
    << "</scene>\n";
  r.text = s.str();
  add_g_loss(c, r);
  for (int i = 0; i < 3; ++i) {
    const double st = reread(c.sigma_t[i]), a = reread(albedo[i]);
    r.sigma_a_back[i] = st * (1 - a);
    r.sigma_s_reduced_back[i] = st * a * (1 - reread(c.g_mean));
  }
  return r;
}

ExportResult to_materialx(const Material& m, double mm_per_unit, bool openpbr) {
  const Channels c = channels_of(m);
  const Appearance a =
      appearance_of(m, openpbr ? ExportTarget::kOpenPbr : ExportTarget::kMaterialX);
  ExportResult r;
  const double longest = std::max({a.mfp_mm[0], a.mfp_mm[1], a.mfp_mm[2]});
  Rgb relative{};
  for (int i = 0; i < 3; ++i) relative[i] = a.mfp_mm[i] / longest;
  const double scale = longest / mm_per_unit;  // the longest mean free path in scene units
  const std::string node = mtlx_name(m.name);
  const auto input = [](const char* name, const char* type, const std::string& value) {
    return std::string("    <input name=\"") + name + "\" type=\"" + type + "\" value=\"" + value +
           "\" />\n";
  };
  std::ostringstream s;
  s << "<?xml version=\"1.0\"?>\n"
    << "<!-- lucent export of '" << xml_comment(m.name) << "': subsurface colour = the standard "
    << "dipole's total diffuse reflectance, radius = the diffuse mean free path 1 / sigma_tr per "
    << "channel, in scene units of " << num(mm_per_unit) << " mm. -->\n";
  if (!openpbr) {
    s << "<materialx version=\"1.38\" colorspace=\"lin_rec709\">\n"
      << "  <standard_surface name=\"SR_" << node << "\" type=\"surfaceshader\">\n"
      << input("base", "float", "0") << input("specular_IOR", "float", num(m.ior))
      << input("subsurface", "float", "1")
      << input("subsurface_color", "color3", triple(a.colour, ", "))
      << input("subsurface_radius", "color3", triple(relative, ", "))
      << input("subsurface_scale", "float", num(scale))
      << input("subsurface_anisotropy", "float", num(c.g_mean)) << "  </standard_surface>\n";
  } else {
    s << "<materialx version=\"1.39\" colorspace=\"lin_rec709\">\n"
      << "  <open_pbr_surface name=\"SR_" << node << "\" type=\"surfaceshader\">\n"
      << input("base_weight", "float", "0") << input("specular_ior", "float", num(m.ior))
      << input("subsurface_weight", "float", "1")
      << input("subsurface_color", "color3", triple(a.colour, ", "))
      << input("subsurface_radius", "float", num(scale))
      << input("subsurface_radius_scale", "color3", triple(relative, ", "))
      << input("subsurface_scatter_anisotropy", "float", num(c.g_mean))
      << "  </open_pbr_surface>\n";
  }
  s << "  <surfacematerial name=\"" << node << "\" type=\"material\">\n"
    << "    <input name=\"surfaceshader\" type=\"surfaceshader\" nodename=\"SR_" << node
    << "\" />\n"
    << "  </surfacematerial>\n"
    << "</materialx>\n";
  r.text = s.str();
  add_g_loss(c, r);
  r.losses.push_back(
      "a colour and a radius: renderers map them to coefficients their own way (Arnold's and "
      "Blender's random walks, Christensen-Burley); the round trip is lucent's standard-dipole "
      "inversion");
  Rgb colour{}, mfp{};
  for (int i = 0; i < 3; ++i) {
    colour[i] = reread(a.colour[i]);
    mfp[i] = reread(relative[i]) * reread(scale) * mm_per_unit;
  }
  invert_appearance(colour, mfp, m.ior, r);
  return r;
}

ExportResult to_gltf(const Material& m, double mm_per_unit) {
  if (std::abs(mm_per_unit - 1000) > 1e-9)
    throw Error("--scene-unit: glTF's unit is the metre (--scene-unit m)");
  const Channels c = channels_of(m);
  const Appearance a = appearance_of(m, ExportTarget::kGltf);
  ExportResult r;
  // Extinction sigma_t = -ln(attenuationColor) / attenuationDistance, in metres; the distance is
  // one mean extinction length, so the colours stay well inside (0, 1).
  const double mean_sigma_t_per_m = (c.sigma_t[0] + c.sigma_t[1] + c.sigma_t[2]) / 3 * 1000;
  const double distance_m = 1 / mean_sigma_t_per_m;
  Rgb attenuation{};
  for (int i = 0; i < 3; ++i) attenuation[i] = std::exp(-c.sigma_t[i] * 1000 * distance_m);
  using nlohmann::json;
  const json doc = {
      {"asset",
       {{"version", "2.0"},
        {"generator", "lucent export"},
        {"extras",
         {{"note",
           "multiscatterColor and the diffuse transmission colour = the standard "
           "dipole's total diffuse reflectance; attenuation = extinction sigma_t "
           "(lucent's sigma_a + sigma_s); thicknessFactor is a placeholder 1 cm"},
          {"lucent_material", m.name}}}}},
      {"extensionsUsed",
       {"KHR_materials_ior", "KHR_materials_volume", "KHR_materials_diffuse_transmission",
        "KHR_materials_volume_scatter"}},
      {"materials",
       {{{"name", m.name},
         {"pbrMetallicRoughness",
          {{"baseColorFactor", {a.colour[0], a.colour[1], a.colour[2], 1.0}},
           {"metallicFactor", 0.0},
           {"roughnessFactor", 0.1}}},
         {"extensions",
          {{"KHR_materials_ior", {{"ior", m.ior}}},
           {"KHR_materials_volume",
            {{"thicknessFactor", 0.01},
             {"attenuationDistance", distance_m},
             {"attenuationColor", {attenuation[0], attenuation[1], attenuation[2]}}}},
           {"KHR_materials_diffuse_transmission",
            {{"diffuseTransmissionFactor", 1.0},
             {"diffuseTransmissionColorFactor", {a.colour[0], a.colour[1], a.colour[2]}}}},
           {"KHR_materials_volume_scatter",
            {{"multiscatterColor", {a.colour[0], a.colour[1], a.colour[2]}},
             {"scatterAnisotropy", c.g_mean}}}}}}}}};
  r.text = doc.dump(2) + "\n";
  add_g_loss(c, r);
  r.losses.push_back(
      "KHR_materials_volume_scatter is a draft: viewers without it show the "
      "diffuse transmission and the attenuation only");
  r.losses.push_back("thicknessFactor is the mesh's business: 0.01 m is written");
  // Round trip: sigma_t from the attenuation, alpha' from the multiscatter colour by lucent's
  // inversion of the dipole (sigma_t' = sigma_a + sigma_s (1 - g)).
  for (int i = 0; i < 3; ++i) {
    const double sigma_t = -std::log(attenuation[i]) / distance_m / 1000;  // mm^-1
    const double alpha = reduced_albedo_from_total_reflectance(a.colour[i], m.ior);
    const double g = c.g_mean;
    // sigma_t = sigma_a + sigma_s, sigma_s' = sigma_s (1 - g), alpha' = sigma_s' / (sigma_a +
    // sigma_s'): sigma_s = alpha' sigma_t / (1 - g + alpha' g).
    const double sigma_s = alpha * sigma_t / (1 - g + alpha * g);
    r.sigma_a_back[i] = sigma_t - sigma_s;
    r.sigma_s_reduced_back[i] = sigma_s * (1 - g);
  }
  return r;
}

}  // namespace

ExportTarget parse_export_target(const std::string& name) {
  if (name == "pbrt") return ExportTarget::kPbrt;
  if (name == "mitsuba") return ExportTarget::kMitsuba;
  if (name == "materialx") return ExportTarget::kMaterialX;
  if (name == "openpbr") return ExportTarget::kOpenPbr;
  if (name == "gltf") return ExportTarget::kGltf;
  throw Error("--to: expected pbrt, mitsuba, materialx, openpbr or gltf, got '" + name + "'");
}

const char* to_string(ExportTarget t) {
  switch (t) {
    case ExportTarget::kPbrt:
      return "pbrt";
    case ExportTarget::kMitsuba:
      return "mitsuba";
    case ExportTarget::kMaterialX:
      return "materialx";
    case ExportTarget::kOpenPbr:
      return "openpbr";
    case ExportTarget::kGltf:
      return "gltf";
  }
  return "?";
}

const char* export_extension(ExportTarget t) {
  switch (t) {
    case ExportTarget::kPbrt:
      return ".pbrt";
    case ExportTarget::kMitsuba:
      return ".xml";
    case ExportTarget::kMaterialX:
    case ExportTarget::kOpenPbr:
      return ".mtlx";
    case ExportTarget::kGltf:
      return ".gltf";
  }
  return "";
}

double millimetres_per_unit(const std::string& unit) {
  if (unit == "mm") return 1;
  if (unit == "cm") return 10;
  if (unit == "m") return 1000;
  throw Error("--scene-unit: expected m, cm or mm, got '" + unit + "'");
}

ExportResult export_material(const Material& m, ExportTarget t, double mm_per_unit) {
  switch (t) {
    case ExportTarget::kPbrt:
      return to_pbrt(m, mm_per_unit);
    case ExportTarget::kMitsuba:
      return to_mitsuba(m, mm_per_unit);
    case ExportTarget::kMaterialX:
      return to_materialx(m, mm_per_unit, false);
    case ExportTarget::kOpenPbr:
      return to_materialx(m, mm_per_unit, true);
    case ExportTarget::kGltf:
      return to_gltf(m, mm_per_unit);
  }
  throw Error("export: unknown target");
}

}  // namespace lucent::materials
