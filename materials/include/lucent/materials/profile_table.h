// `lucent profile`: a model evaluated at given radii or configurations, as CSV.
#pragma once

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/material.h"
#include "lucent/materials/transport_table.h"

namespace lucent::materials {

/// The models of a translucent material. kTabulated (the transport table, docs/DESIGN.md §4.2) is
/// radial only: normal incidence on a plane; the renderer has the two dipoles.
enum class DiffusionModel { kDipole, kDirectionalDipole, kTabulated };

/// "dipole" or "ddipole" (and "tabulated" when allowed); anything else throws lucent::Error
/// naming the option.
DiffusionModel parse_diffusion_model(const std::string& name,
                                     const std::string& option = "--model",
                                     bool allow_tabulated = false);
std::string to_string(DiffusionModel model);

/// The model a renderer uses for `material` unless told otherwise: the one it was fitted with;
/// for a material that was not fitted, the tabulated model where the default transport table
/// covers it (eta and every channel's g), else the directional dipole (which has no albedo factor:
/// at low albedo it is several times too bright, and ketchup looks pink).
DiffusionModel preferred_model(const Material& material);

/// "0.1,0.5,1,2" -> radii in mm; each must be finite and >= 0.
std::vector<double> parse_radius_list(const std::string& text, const std::string& option = "--r");
/// "FROM:TO:COUNT[:lin|log]" -> COUNT radii in mm from FROM to TO inclusive (log needs FROM > 0).
std::vector<double> parse_radius_range(const std::string& text,
                                       const std::string& option = "--r-range");

struct RadialProfileOptions {
  DiffusionModel model = DiffusionModel::kDipole;
  /// Exitance R(r), or pi L along the normal (what a camera looking straight down sees).
  TableQuantity quantity = TableQuantity::kExitance;
  std::vector<double> r_mm;  ///< radii, mm
  bool total = false;        ///< add the total diffuse reflectance per channel
};

/// lucent's radial CSV (the one schema `lucent fit` reads, README "radial CSV"): a comment line
/// `# format=lucent-radial-profile version=1 quantity=exitance|radiance ior=ETA model=... ...`,
/// then `r_mm,R_r,R_g,R_b`, values per mm^2 per unit power entering the sample, normal incidence.
/// exitance: dipole R_d(r); ddipole pi S_d times its hemispherical exit transmittance
/// eta^2 (1 - F_dr); tabulated the transport table's exitance. radiance: the dipoles times
/// F_t(normal) (pi S with the outgoing transmittance); tabulated its radiance along the normal.
/// With `total`, a comment line `# total=R,G,B` (closed form for the dipole, quadrature for the
/// ddipole, the table's total for tabulated; always the exitance total).
std::string radial_profile_csv(const Material& material, const RadialProfileOptions& options);

/// The radial value of one channel at r (mm) as radial_profile_csv writes it.
double radial_profile_value(const Material& material, int channel, DiffusionModel model,
                            TableQuantity quantity, double r_mm);

/// The total diffuse reflectance of one channel, per unit power entering (what `--total` writes):
/// closed form for the dipole, the table's for tabulated, quadrature over the plane for the ddipole.
double total_diffuse_reflectance(const Material& material, int channel, DiffusionModel model);

/// One BSSRDF configuration: positions in mm, unit normals and light direction.
struct BssrdfConfig {
  Vec3<double> x_i, n_i, w_i, x_o, n_o;
};

/// Parses the configuration table (header
/// xi_x,xi_y,xi_z,ni_x,ni_y,ni_z,wi_x,wi_y,wi_z,xo_x,xo_y,xo_z,no_x,no_y,no_z). `source` names the
/// file in errors; errors give the line number and the column. Normals and w_i must be unit length
/// to 1e-6.
std::vector<BssrdfConfig> read_bssrdf_configs(std::istream& in, const std::string& source);

/// Evaluates S_d per channel for each configuration; returns the input columns plus Sd_r,Sd_g,Sd_b
/// with 17 significant digits. dipole: R_d(|x_o - x_i|) / pi.
std::string bssrdf_configs_csv(const Material& material, DiffusionModel model,
                               const std::vector<BssrdfConfig>& configs);

/// S_d for one configuration, all three channels.
std::array<double, 3> evaluate_bssrdf(const Material& material, DiffusionModel model,
                                      const BssrdfConfig& config);

}  // namespace lucent::materials
