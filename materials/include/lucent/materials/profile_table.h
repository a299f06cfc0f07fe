// `lucent profile`: a model evaluated at given radii or configurations, as CSV.
#pragma once

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/material.h"

namespace lucent::materials {

enum class DiffusionModel { kDipole, kDirectionalDipole };

/// "dipole" or "ddipole"; anything else throws lucent::Error naming the option.
DiffusionModel parse_diffusion_model(const std::string& name,
                                     const std::string& option = "--model");
std::string to_string(DiffusionModel model);

/// "0.1,0.5,1,2" -> radii in mm; each must be finite and >= 0.
std::vector<double> parse_radius_list(const std::string& text, const std::string& option = "--r");
/// "FROM:TO:COUNT[:lin|log]" -> COUNT radii in mm from FROM to TO inclusive (log needs FROM > 0).
std::vector<double> parse_radius_range(const std::string& text,
                                       const std::string& option = "--r-range");

struct RadialProfileOptions {
  DiffusionModel model = DiffusionModel::kDipole;
  std::vector<double> r_mm;  ///< radii, mm
  bool total = false;        ///< append the total diffuse reflectance per channel
};

/// CSV `r_mm,Rd_r,Rd_g,Rd_b`: radially symmetric diffuse reflectance per mm^2 for unit incident
/// flux. dipole: R_d(r). ddipole: pi S_d at normal incidence on a plane (light along the normal,
/// x_o at distance r), the quantity the directional dipole puts in R_d's place. With `total`, a
/// last row `total,...`: the closed form for the dipole, numerical quadrature over the plane for
/// the ddipole.
std::string radial_profile_csv(const Material& material, const RadialProfileOptions& options);

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
