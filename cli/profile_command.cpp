// `lucent profile`: evaluate the standard or directional dipole and write CSV.
#include <sstream>
#include <fstream>
#include <iostream>
#include <memory>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/materials/profile_table.h"

namespace lucent::cli {
namespace {

struct ProfileArguments {
  std::string material;
  std::string model;
  std::string radii;
  std::string radius_range;
  std::string configs;
  bool total = false;
  std::string quantity = "exitance";
  std::string output;
};

void run_profile(const ProfileArguments& args) {
  using namespace lucent::materials;
  if (!args.output.empty() && args.output != "-") check_output_file(args.output, "", "-o");
  const Material material = load_material(args.material);
  const std::string model_name =
      !args.model.empty() ? args.model : (!material.model.empty() ? material.model : "dipole");
  const DiffusionModel model = parse_diffusion_model(model_name, "--model", true);

  std::string csv;
  if (!args.configs.empty()) {
    std::istringstream in(read_input_file(args.configs));  // bounded, recorded as an input
    csv = bssrdf_configs_csv(material, model, read_bssrdf_configs(in, args.configs));
  } else {
    RadialProfileOptions options;
    options.model = model;
    options.total = args.total;
    if (args.quantity == "radiance")
      options.quantity = TableQuantity::kRadiance;
    else if (args.quantity != "exitance")
      throw Error("--quantity: expected 'exitance' or 'radiance', got '" + args.quantity + "'");
    options.r_mm =
        !args.radii.empty() ? parse_radius_list(args.radii) : parse_radius_range(args.radius_range);
    csv = radial_profile_csv(material, options);
  }
  if (args.output.empty() || args.output == "-") {
    std::cout << csv;
  } else {
    write_file_atomically(args.output, csv);
  }
}

}  // namespace

void register_profile_command(CLI::App& app) {
  auto args = std::make_shared<ProfileArguments>();
  CLI::App* cmd = app.add_subcommand(
      "profile",
      "Evaluate a model and write CSV. Radial mode (--r or --r-range) writes lucent's radial CSV "
      "(a '# format=lucent-radial-profile ...' line, then r_mm,R_r,R_g,R_b): per mm^2 per unit "
      "power entering, normal incidence, the exitance or pi L along the normal (--quantity); it "
      "feeds lucent fit unchanged. Configuration mode (--configs) writes S_d per mm^2 per sr.");
  cmd->add_option("--material", args->material,
                  "bundled material name (e.g. marble) or path to a lucent-material JSON file")
      ->required();
  cmd->add_option("--model", args->model,
                  "dipole (standard dipole), ddipole (directional dipole) or tabulated (the "
                  "Monte Carlo transport table, radial only); default: the material's fitted "
                  "model, else dipole");
  cmd->add_option("--quantity", args->quantity,
                  "radial mode: exitance (R(r), all directions) or radiance (pi L along the "
                  "normal)")
      ->capture_default_str();
  auto* r = cmd->add_option("--r", args->radii, "comma-separated radii in mm, e.g. 0.1,0.5,1,2");
  auto* range = cmd->add_option("--r-range", args->radius_range,
                                "FROM:TO:COUNT[:lin|log] radii in mm, e.g. 0.01:50:200:log");
  auto* configs = cmd->add_option(
      "--configs", args->configs,
      "CSV of configurations: xi_x,xi_y,xi_z,ni_x,ni_y,ni_z,wi_x,wi_y,wi_z,xo_x,xo_y,xo_z,"
      "no_x,no_y,no_z (positions in mm; normals and wi unit vectors, wi toward the light)");
  r->excludes(range)->excludes(configs);
  range->excludes(configs);
  cmd->add_flag("--total", args->total,
                "add a line '# total=R,G,B', the total diffuse reflectance per channel "
                "(closed form for dipole, quadrature for ddipole, the table's for tabulated)");
  cmd->add_option("-o,--output", args->output, "output CSV file (default: standard output)");
  cmd->callback([args, r, range, configs] {
    if (r->count() + range->count() + configs->count() == 0) {
      throw lucent::Error("profile: give one of --r, --r-range (radial) or --configs");
    }
    if (configs->count() > 0 && args->total) {
      throw lucent::Error("--total: only with --r or --r-range, not with --configs");
    }
    run_profile(*args);
  });
}

}  // namespace lucent::cli
