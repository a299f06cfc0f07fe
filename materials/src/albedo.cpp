#include "lucent/materials/albedo.h"

#include <cmath>
#include <string>

#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"

namespace lucent::materials {

double reduced_albedo_from_total_reflectance(double total_reflectance, double eta) {
  if (!(total_reflectance >= 0.0 && total_reflectance <= 1.0)) {
    throw Error("total diffuse reflectance: expected a value in [0, 1], got " +
                std::to_string(total_reflectance));
  }
  if (!(eta > 0.0 && std::isfinite(eta))) {
    throw Error("eta: expected a positive relative index of refraction, got " +
                std::to_string(eta));
  }
  const double A = derive_coefficients(Medium<double>{0.0, 1.0, 0.0, eta}).A_dipole;
  // Bisection: R_tot is monotonic in alpha' but its derivative is infinite at alpha' = 1, where
  // Newton's method would overshoot; 60 halvings reach double precision on [0, 1].
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (dipole_total_reflectance(mid, A) < total_reflectance ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

ReducedCoefficients coefficients_from_diffuse_colour(double diffuse_reflectance,
                                                     double diffuse_mean_free_path_mm, double eta) {
  if (!(diffuse_reflectance > 0.0 && diffuse_reflectance < 1.0)) {
    throw Error("diffuse colour: expected a total diffuse reflectance in (0, 1), got " +
                std::to_string(diffuse_reflectance));
  }
  if (!(diffuse_mean_free_path_mm > 0.0 && std::isfinite(diffuse_mean_free_path_mm))) {
    throw Error("mean free path: expected a diffuse mean free path > 0 mm, got " +
                std::to_string(diffuse_mean_free_path_mm));
  }
  const double alpha_prime = reduced_albedo_from_total_reflectance(diffuse_reflectance, eta);
  const double sigma_tr = 1.0 / diffuse_mean_free_path_mm;
  if (!(alpha_prime < 1.0)) {
    throw Error("diffuse colour: " + std::to_string(diffuse_reflectance) +
                " is too close to 1 to give a finite absorption");
  }
  const double sigma_t_reduced = sigma_tr / std::sqrt(3.0 * (1.0 - alpha_prime));
  return {(1.0 - alpha_prime) * sigma_t_reduced, alpha_prime * sigma_t_reduced};
}

}  // namespace lucent::materials
