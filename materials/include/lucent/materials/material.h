// A material: RGB optical properties plus what produced them, and its file format
// ("format": "lucent-material", "version": 1; docs/DESIGN.md §3).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lucent/materials/medium.h"

namespace lucent::materials {

using Rgb = std::array<double, 3>;

struct Material {
  static constexpr int kFormatVersion = 1;

  std::string name;
  double ior = 1.3;            ///< relative index, n_sample / n_outside
  Rgb sigma_a{};               ///< absorption, mm^-1
  Rgb sigma_s_reduced{};       ///< reduced scattering sigma_s (1 - g), mm^-1
  std::optional<Rgb> sigma_s;  ///< unreduced scattering, mm^-1 (with g)
  std::optional<Rgb> g;        ///< Henyey-Greenstein mean cosine
  /// The model it was fitted with ("dipole", "ddipole", "tabulated"), or "".
  std::string model;
  /// For a tabulated fit: the cheapest diffusion model within 3% of the tabulated profile beyond a
  /// radius the fit reports (provenance.fit.adequacy says beyond which), "none" when none is, ""
  /// when not judged.
  std::string adequate_model;
  /// What a renderer without the table uses: the adequate model, or when none is, the closest one.
  /// "" when not judged.
  std::string fallback_model;
  nlohmann::json uncertainty;  ///< standard deviations and correlations; null when not fitted
  nlohmann::json provenance;   ///< source table or capture, fit statistics, tool version

  /// One channel (0 = R, 1 = G, 2 = B) as a Medium; isotropic when only sigma_s' is known.
  Medium<double> medium(int channel) const;

  /// The model a renderer uses by default: the one the material was fitted with (dipole, ddipole
  /// or tabulated), or `fallback` for a material that was not fitted. (adequate_model says which
  /// faster dipole is within the data's noise, for a user who trades accuracy for speed.)
  std::string diffusion_model(const std::string& fallback = "ddipole") const;

  std::string to_string() const;
};

/// Parses a material document. `source` names the file in error messages.
/// Throws lucent::Error "<source>: field '<name>': <what was expected>" on anything it does not
/// accept.
Material material_from_json(const nlohmann::json& doc, const std::string& source);

/// The document written to disk: format, version, the fields above, and "derived" quantities per
/// channel (alpha', sigma_tr, diffuse mean free path, total diffuse reflectance) ignored on read.
nlohmann::json material_to_json(const Material& material);

/// Reads and validates a material file.
Material read_material(const std::filesystem::path& path);

/// Writes a material file atomically.
void write_material(const std::filesystem::path& path, const Material& material);

/// The folder of bundled materials: $LUCENT_MATERIAL_LIBRARY if set, else the source tree's
/// materials/library (compiled in), else <exe>/../share/lucent/materials.
std::filesystem::path material_library_dir();

/// Names of the bundled materials (file stems), sorted.
std::vector<std::string> library_material_names();

/// Loads `name_or_path`: an existing file path, or the name of a bundled material.
/// Unknown names throw lucent::Error listing the bundled names.
Material load_material(const std::string& name_or_path);

}  // namespace lucent::materials
