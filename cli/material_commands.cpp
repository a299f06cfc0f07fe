// `lucent export` (a material in another renderer's terms) and `lucent materials` (the library).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/export.h"
#include "lucent/materials/material.h"

namespace lucent::cli {
namespace {

struct ExportArguments {
  std::string material, to, output, scene_unit = "m";
  bool quiet = false;
};

void run_export(const ExportArguments& a) {
  const materials::ExportTarget target = materials::parse_export_target(a.to);
  const double mm_per_unit = materials::millimetres_per_unit(a.scene_unit);
  check_output_file(a.output, materials::export_extension(target), "-o");
  const materials::Material m = materials::load_material(a.material);
  const materials::ExportResult r = materials::export_material(m, target, mm_per_unit);
  write_file_atomically(a.output, r.text);
  if (a.quiet) return;
  std::printf("wrote %s (%s, scene unit %s = %g mm)\n", printable(a.output).c_str(), materials::to_string(target),
              a.scene_unit.c_str(), mm_per_unit);
  std::printf("round trip (the target's parameters inverted back), mm^-1:\n");
  std::printf("  %-4s %-16s %14s %14s %10s\n", "ch", "coefficient", "lucent", "back", "diff %");
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const double pairs[2][2] = {{m.sigma_a[c], r.sigma_a_back[c]},
                                {m.sigma_s_reduced[c], r.sigma_s_reduced_back[c]}};
    for (int k = 0; k < 2; ++k) {
      const double diff = pairs[k][0] != 0 ? 100 * (pairs[k][1] / pairs[k][0] - 1) : 0.0;
      std::printf("  %-4s %-16s %14.7g %14.7g %+10.2e\n", names[c], k ? "sigma_s'" : "sigma_a",
                  pairs[k][0], pairs[k][1], diff);
    }
  }
  for (const std::string& loss : r.losses) std::printf("  loses: %s\n", loss.c_str());
}

void run_materials(bool json) {
  nlohmann::json list = nlohmann::json::array();
  if (!json)
    std::printf("%-12s %5s  %-26s %-26s %-20s %-20s  %s\n", "name", "ior", "sigma_a (1/mm)",
                "sigma_s' (1/mm)", "albedo alpha'", "mfp 1/sigma_tr (mm)", "source");
  for (const std::string& name : materials::library_material_names()) {
    const materials::Material m = materials::load_material(name);
    materials::Rgb alpha{}, mfp{};
    for (int c = 0; c < 3; ++c) {
      const materials::StandardDipole<double> d(m.medium(c));
      alpha[c] = d.coefficients().alpha_prime;
      mfp[c] = d.coefficients().sigma_tr > 0 ? 1 / d.coefficients().sigma_tr : INFINITY;
    }
    const std::string source =
        m.provenance.is_object() && m.provenance.contains("source") &&
                m.provenance["source"].is_string()
            ? m.provenance["source"].get<std::string>()
            : std::string("-");
    if (json) {
      nlohmann::json mfp_json = nlohmann::json::array();
      for (double v : mfp) mfp_json.push_back(std::isfinite(v) ? nlohmann::json(v) : nullptr);
      list.push_back({{"name", name},
                      {"ior", m.ior},
                      {"sigma_a", m.sigma_a},
                      {"sigma_s_reduced", m.sigma_s_reduced},
                      {"alpha_prime", alpha},
                      {"diffuse_mean_free_path_mm", mfp_json},
                      {"source", source}});
      continue;
    }
    const auto three = [](const materials::Rgb& v) {
      char b[64];
      std::snprintf(b, sizeof b, "%.3g %.3g %.3g", v[0], v[1], v[2]);
      return std::string(b);
    };
    // The library's text is data: a control character in it would forge rows or drive the
    // terminal.
    std::printf("%-12s %5.3g  %-26s %-26s %-20s %-20s  %s\n", printable(name).c_str(), m.ior,
                three(m.sigma_a).c_str(), three(m.sigma_s_reduced).c_str(), three(alpha).c_str(),
                three(mfp).c_str(), printable(source).c_str());
  }
  if (json)
    std::cout << list.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
}

}  // namespace

void register_material_commands(CLI::App& app) {
  auto args = std::make_shared<ExportArguments>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Writes a material for another renderer: pbrt-v4 (subsurface material and homogeneous "
      "medium, coefficients with a scale for the scene unit), Mitsuba 3 (homogeneous medium in a "
      "dielectric, a minimal scene), MaterialX standard_surface or OpenPBR (subsurface colour and "
      "radius), glTF (KHR_materials_volume, _diffuse_transmission, _volume_scatter). Prints the "
      "round trip: the written parameters inverted back to sigma_a and sigma_s'.");
  cmd->add_option("--material", args->material, "a bundled material's name or a material file")
      ->required();
  cmd->add_option("--to", args->to, "pbrt, mitsuba, materialx, openpbr or gltf")->required();
  cmd->add_option("-o,--output", args->output,
                  "file to write (.pbrt, .xml, .mtlx or .gltf, by target)")
      ->required();
  cmd->add_option("--scene-unit", args->scene_unit,
                  "the scene's length unit: m, cm or mm (glTF: m)")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no round-trip table");
  cmd->callback([args] { run_export(*args); });

  auto json = std::make_shared<bool>(false);
  CLI::App* list = app.add_subcommand(
      "materials",
      "Lists the bundled materials: name, relative index, sigma_a and sigma_s' (1/mm), reduced "
      "albedo alpha', diffuse mean free path 1/sigma_tr (mm) and the source.");
  list->add_flag("--json", *json, "as JSON");
  list->callback([json] { run_materials(*json); });
}

}  // namespace lucent::cli
