// lucent export: each target's file parses (pbrt tokens, XML through expat, JSON) and carries the
// right values and units; the round trips come back within their printing precision; the
// appearance form of a material file (diffuse_colour + mfp_mm) inverts what the exporters write.
#include <expat.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/export.h"
#include "lucent/materials/material.h"

namespace lucent::materials {
namespace {

// Every element's attributes, in document order; fails the test on malformed XML.
struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
};
std::vector<XmlElement> parse_xml(const std::string& text) {
  std::vector<XmlElement> out;
  XML_Parser p = XML_ParserCreate(nullptr);
  XML_SetUserData(p, &out);
  XML_SetStartElementHandler(p, [](void* data, const XML_Char* name, const XML_Char** attrs) {
    XmlElement e{name, {}};
    for (int i = 0; attrs[i]; i += 2) e.attributes[attrs[i]] = attrs[i + 1];
    static_cast<std::vector<XmlElement>*>(data)->push_back(e);
  });
  const bool ok = XML_Parse(p, text.data(), int(text.size()), 1) == XML_STATUS_OK;
  EXPECT_TRUE(ok) << XML_ErrorString(XML_GetErrorCode(p)) << " at line "
                  << XML_GetCurrentLineNumber(p);
  XML_ParserFree(p);
  return out;
}
// The value of the element `tag` whose attribute name="field".
std::string xml_value(const std::vector<XmlElement>& xml, const std::string& tag,
                      const std::string& field) {
  for (const XmlElement& e : xml)
    if (e.name == tag && e.attributes.count("name") && e.attributes.at("name") == field)
      return e.attributes.count("value") ? e.attributes.at("value") : "";
  ADD_FAILURE() << "no <" << tag << " name=\"" << field << "\">";
  return "";
}
std::vector<double> numbers(const std::string& text) {
  std::vector<double> out;
  std::string t = text;
  for (char& c : t)
    if (c == ',') c = ' ';
  std::istringstream in(t);
  for (double v; in >> v;) out.push_back(v);
  return out;
}

// pbrt-v4 parameter lists: "type name" [ values ] after the directive.
std::map<std::string, std::vector<std::string>> pbrt_parameters(const std::string& text,
                                                                const std::string& directive) {
  std::map<std::string, std::vector<std::string>> out;
  const std::size_t start = text.find(directive);
  EXPECT_NE(start, std::string::npos) << directive;
  if (start == std::string::npos) return out;
  const std::size_t end = text.find("\nMake", start + 1);
  const std::string body = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
  const std::regex param("\"(\\w+) (\\w+)\"\\s*\\[([^\\]]*)\\]");
  for (std::sregex_iterator it(body.begin(), body.end(), param), e; it != e; ++it) {
    std::istringstream values((*it)[3].str());
    std::vector<std::string> v;
    for (std::string w; values >> w;) v.push_back(w);
    out[(*it)[1].str() + " " + (*it)[2].str()] = v;
  }
  return out;
}

Material marble() { return load_material("marble"); }

TEST(Export, PbrtCarriesCoefficientsWithTheSceneScale) {
  const Material m = marble();
  const ExportResult r = export_material(m, ExportTarget::kPbrt, millimetres_per_unit("m"));
  const auto p = pbrt_parameters(r.text, "MakeNamedMaterial");
  ASSERT_EQ(p.at("string type").at(0), "\"subsurface\"");
  EXPECT_EQ(std::stod(p.at("float scale").at(0)), 1000);  // mm^-1 in a metre scene
  EXPECT_EQ(std::stod(p.at("float eta").at(0)), 1.5);
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(std::stod(p.at("rgb sigma_a").at(c)), m.sigma_a[c]);
    EXPECT_DOUBLE_EQ(std::stod(p.at("rgb sigma_s").at(c)), m.sigma_s_reduced[c]);  // g = 0
  }
  const auto medium = pbrt_parameters(r.text, "MakeNamedMedium");
  EXPECT_EQ(medium.at("string type").at(0), "\"homogeneous\"");
  EXPECT_EQ(std::stod(medium.at("float scale").at(0)), 1000);
  // cm: scale 10.
  const auto cm = pbrt_parameters(export_material(m, ExportTarget::kPbrt, 10).text,
                                  "MakeNamedMaterial");
  EXPECT_EQ(std::stod(cm.at("float scale").at(0)), 10);
}

TEST(Export, PbrtAnisotropicMaterialKeepsSigmaS) {
  Material m = marble();
  m.g = Rgb{0.5, 0.5, 0.5};
  m.sigma_s = Rgb{};
  for (int c = 0; c < 3; ++c) (*m.sigma_s)[c] = m.sigma_s_reduced[c] / 0.5;
  const ExportResult r = export_material(m, ExportTarget::kPbrt, 1);
  const auto p = pbrt_parameters(r.text, "MakeNamedMaterial");
  EXPECT_EQ(std::stod(p.at("float g").at(0)), 0.5);
  EXPECT_DOUBLE_EQ(std::stod(p.at("rgb sigma_s").at(1)), 2 * m.sigma_s_reduced[1]);
  // One g for all channels: a material with three says what it loses.
  (*m.g)[2] = 0.7;
  (*m.sigma_s)[2] = m.sigma_s_reduced[2] / 0.3;
  const ExportResult lossy = export_material(m, ExportTarget::kPbrt, 1);
  ASSERT_FALSE(lossy.losses.empty());
  EXPECT_NE(lossy.losses.front().find("one Henyey-Greenstein g"), std::string::npos);
  EXPECT_GT(std::abs(lossy.sigma_s_reduced_back[2] / m.sigma_s_reduced[2] - 1), 0.1);
}

TEST(Export, MitsubaSceneHasAHomogeneousMediumInADielectric) {
  const Material m = marble();
  const ExportResult r = export_material(m, ExportTarget::kMitsuba, 1000);
  const auto xml = parse_xml(r.text);
  ASSERT_FALSE(xml.empty());
  EXPECT_EQ(xml.front().name, "scene");
  bool medium = false, dielectric = false, shape = false;
  for (const XmlElement& e : xml) {
    medium = medium || (e.name == "medium" && e.attributes.at("type") == "homogeneous");
    dielectric = dielectric || (e.name == "bsdf" && e.attributes.at("type") == "dielectric");
    shape = shape || e.name == "shape";
  }
  EXPECT_TRUE(medium && dielectric && shape);
  EXPECT_EQ(numbers(xml_value(xml, "float", "scale")).at(0), 1000);
  EXPECT_EQ(numbers(xml_value(xml, "float", "int_ior")).at(0), 1.5);
  const auto albedo = numbers(xml_value(xml, "rgb", "albedo"));
  const auto sigma_t = numbers(xml_value(xml, "rgb", "sigma_t"));
  ASSERT_EQ(albedo.size(), 3u);
  ASSERT_EQ(sigma_t.size(), 3u);
  for (int c = 0; c < 3; ++c) {
    const double st = m.sigma_a[c] + m.sigma_s_reduced[c];
    EXPECT_NEAR(sigma_t[c], st, 1e-8 * st);
    EXPECT_NEAR(albedo[c], m.sigma_s_reduced[c] / st, 1e-8);
  }
}

TEST(Export, MaterialXAndOpenPbrCarryColourAndRadius) {
  const Material m = marble();
  for (const ExportTarget t : {ExportTarget::kMaterialX, ExportTarget::kOpenPbr}) {
    const ExportResult r = export_material(m, t, 10);  // a centimetre scene
    const auto xml = parse_xml(r.text);
    const bool open = t == ExportTarget::kOpenPbr;
    const auto colour = numbers(xml_value(xml, "input", "subsurface_color"));
    ASSERT_EQ(colour.size(), 3u);
    std::vector<double> radius;
    if (open) {
      const double scale = numbers(xml_value(xml, "input", "subsurface_radius")).at(0);
      for (double v : numbers(xml_value(xml, "input", "subsurface_radius_scale")))
        radius.push_back(v * scale);
      EXPECT_EQ(numbers(xml_value(xml, "input", "specular_ior")).at(0), 1.5);
    } else {
      const double scale = numbers(xml_value(xml, "input", "subsurface_scale")).at(0);
      for (double v : numbers(xml_value(xml, "input", "subsurface_radius")))
        radius.push_back(v * scale);
      EXPECT_EQ(numbers(xml_value(xml, "input", "specular_IOR")).at(0), 1.5);
    }
    ASSERT_EQ(radius.size(), 3u);
    for (int c = 0; c < 3; ++c) {
      const StandardDipole<double> d(m.medium(c));
      EXPECT_NEAR(colour[c], d.total_diffuse_reflectance(), 1e-8);
      const double mfp_cm = 1 / d.coefficients().sigma_tr / 10;
      EXPECT_NEAR(radius[c], mfp_cm, 1e-7 * mfp_cm);
      EXPECT_NEAR(r.sigma_a_back[c], m.sigma_a[c], 1e-6 * m.sigma_a[c]) << to_string(t);
      EXPECT_NEAR(r.sigma_s_reduced_back[c], m.sigma_s_reduced[c], 1e-6 * m.sigma_s_reduced[c]);
    }
  }
}

TEST(Export, GltfVolumeExtensionsRoundTrip) {
  const Material m = load_material("ketchup");
  const ExportResult r = export_material(m, ExportTarget::kGltf, 1000);
  const nlohmann::json doc = nlohmann::json::parse(r.text);
  EXPECT_EQ(doc["asset"]["version"], "2.0");
  const nlohmann::json& ext = doc["materials"][0]["extensions"];
  const double d = ext["KHR_materials_volume"]["attenuationDistance"];
  for (int c = 0; c < 3; ++c) {
    const double colour = ext["KHR_materials_volume"]["attenuationColor"][c];
    const double sigma_t_m = -std::log(colour) / d;  // per metre
    EXPECT_NEAR(sigma_t_m, 1000 * (m.sigma_a[c] + m.sigma_s_reduced[c]),
                1e-9 * sigma_t_m);
    EXPECT_NEAR(r.sigma_a_back[c], m.sigma_a[c], 1e-9 * m.sigma_a[c]);
    EXPECT_NEAR(r.sigma_s_reduced_back[c], m.sigma_s_reduced[c], 1e-9 * m.sigma_s_reduced[c]);
  }
  EXPECT_TRUE(ext.contains("KHR_materials_diffuse_transmission"));
  EXPECT_TRUE(ext["KHR_materials_volume_scatter"].contains("multiscatterColor"));
  EXPECT_THROW(export_material(m, ExportTarget::kGltf, 10), Error);  // glTF is in metres
}

TEST(Export, RefusesWhatATargetCannotExpress) {
  Material m = marble();
  m.sigma_a[1] = 0;  // no absorption: no diffuse mean free path
  EXPECT_THROW(export_material(m, ExportTarget::kMaterialX, 1000), Error);
  EXPECT_NO_THROW(export_material(m, ExportTarget::kPbrt, 1000));
  EXPECT_THROW(parse_export_target("blender"), Error);
  EXPECT_THROW(millimetres_per_unit("inch"), Error);
}

// The appearance form: what the artist formats carry, read back as coefficients.
TEST(Export, AppearanceMaterialFileInvertsTheExportedColourAndRadius) {
  const Material m = marble();
  nlohmann::json doc = {{"format", "lucent-material"}, {"version", 1}, {"name", "m"},
                        {"ior", m.ior}};
  for (int c = 0; c < 3; ++c) {
    const StandardDipole<double> d(m.medium(c));
    doc["diffuse_colour"].push_back(d.total_diffuse_reflectance());
    doc["mfp_mm"].push_back(1 / d.coefficients().sigma_tr);
  }
  const Material back = material_from_json(doc, "appearance.json");
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(back.sigma_a[c], m.sigma_a[c], 1e-9 * m.sigma_a[c]);
    EXPECT_NEAR(back.sigma_s_reduced[c], m.sigma_s_reduced[c], 1e-9 * m.sigma_s_reduced[c]);
  }
  nlohmann::json both = doc;
  both["sigma_a"] = {1, 1, 1};
  EXPECT_THROW(material_from_json(both, "both.json"), Error);
  nlohmann::json half = doc;
  half.erase("mfp_mm");
  EXPECT_THROW(material_from_json(half, "half.json"), Error);
  nlohmann::json white = doc;
  white["diffuse_colour"][0] = 1.0;
  EXPECT_THROW(material_from_json(white, "white.json"), Error);
}

}  // namespace
}  // namespace lucent::materials
