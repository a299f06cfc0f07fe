// Importance sampling of a material's radial profile (DiscDistribution::kProfile, and the CPU
// reference's probe rays): a density over the plane around a point, proportional to the mean over
// the scattering channels of each channel's normalised normal-incidence profile.
#pragma once

#include <vector>

#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"

namespace lucent::render::detail {

/// p_A(r) = (1/3) sum_c P_c(r) / integral of P_c over the plane, per mm^2, over r < r_max, where
/// P_c is materials::radial_profile_value (quantity radiance) of the channels that scatter,
/// piecewise constant in ln r on 4096 cells from r_lo (1e-4 of the shortest mean free path) to
/// r_max: the smaller of `max_radius_mm` and the widest channel's reach (60 diffusion lengths, or
/// 1000 mean free paths without absorption). Radii below r_lo are never drawn (they hold ~1e-8 of
/// the profile). Inversion and density use the same cells, so 1 / p_A is exactly the weight of a
/// drawn radius.
class RadialProfileDensity {
 public:
  RadialProfileDensity(const materials::Material& material, materials::DiffusionModel model,
                       double max_radius_mm);

  /// False when no channel scatters (nothing to sample: the subsurface term is zero).
  bool valid() const { return total_ > 0; }
  double r_max() const { return r_max_; }
  /// The radius at quantile u in [0, 1) and its density per area there (mm^-2); `cdf` (optional)
  /// gets the exact fraction of the density below that radius.
  double sample(double u, double* density_per_mm2, double* cdf = nullptr) const;
  /// Density per area at r (mm^-2): 0 outside [r_lo, r_max).
  double density_per_mm2(double r) const;

 private:
  double r_lo_ = 0, r_max_ = 0, step_ = 0, total_ = 0;
  std::vector<double> mass_, cumulative_;
};

}  // namespace lucent::render::detail
