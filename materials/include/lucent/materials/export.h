// A material in the parameterisations other renderers use (`lucent export`): pbrt-v4, Mitsuba 3,
// MaterialX standard_surface, OpenPBR and glTF. Coefficients in mm^-1 become coefficients per scene
// unit through each format's scale; the artist-facing formats (a colour and a radius) take the
// standard dipole's total diffuse reflectance and the diffuse mean free path 1 / sigma_tr, the
// pair `coefficients_from_diffuse_colour` inverts, so lucent can read them back (albedo.h).
#pragma once

#include <string>
#include <vector>

#include "lucent/materials/material.h"

namespace lucent::materials {

enum class ExportTarget { kPbrt, kMitsuba, kMaterialX, kOpenPbr, kGltf };

/// "pbrt", "mitsuba", "materialx", "openpbr" or "gltf"; throws lucent::Error naming --to.
ExportTarget parse_export_target(const std::string& name);
const char* to_string(ExportTarget target);
/// The file extension each target writes (".pbrt", ".xml", ".mtlx", ".mtlx", ".gltf").
const char* export_extension(ExportTarget target);

/// Millimetres per scene unit for "mm", "cm" or "m"; throws lucent::Error naming --scene-unit.
double millimetres_per_unit(const std::string& unit);

struct ExportResult {
  std::string text;                 ///< the file's contents
  std::vector<std::string> losses;  ///< what the target cannot carry, one line each
  /// The target's parameters, as written, inverted back to lucent's (mm^-1): the round trip.
  Rgb sigma_a_back{}, sigma_s_reduced_back{};
};

/// The material in `target`'s terms, for a scene whose unit is `mm_per_unit` millimetres.
/// Throws lucent::Error when the material cannot be expressed (a channel with no scattering has no
/// diffuse colour and radius: named).
ExportResult export_material(const Material& material, ExportTarget target, double mm_per_unit);

}  // namespace lucent::materials
