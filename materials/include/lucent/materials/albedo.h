// From appearance to coefficients: inverting the standard dipole's total diffuse reflectance.
#pragma once

namespace lucent::materials {

/// The reduced albedo alpha' = sigma_s' / sigma_t' whose standard-dipole total diffuse reflectance
/// (dipole_total_reflectance, multiple scattering only, no specular term) equals
/// `total_reflectance`, for relative index eta. R_tot grows monotonically from 0 (alpha' = 0) to 1
/// (alpha' = 1); the root is bracketed and found to 1e-14. Throws lucent::Error unless 0 <=
/// total_reflectance <= 1.
double reduced_albedo_from_total_reflectance(double total_reflectance, double eta);

struct ReducedCoefficients {
  double sigma_a;          ///< mm^-1
  double sigma_s_reduced;  ///< mm^-1
};

/// Coefficients from a diffuse colour and a mean free path, per channel (Jensen and Buhler 2002):
/// - the diffuse colour is the total diffuse reflectance R_tot of the standard dipole (what a flat,
///   uniformly lit slab of the material reflects, excluding the specular term), in (0, 1);
/// - the mean free path is the diffuse mean free path l_d = 1 / sigma_tr in mm, the distance over
/// which
///   the diffuse light falls by e (what an artist sees as "how far light bleeds"), > 0.
/// alpha' comes from inverting R_tot, then sigma_t' = 1 / (l_d sqrt(3 (1 - alpha'))),
/// sigma_s' = alpha' sigma_t', sigma_a = (1 - alpha') sigma_t'.
/// Throws lucent::Error naming the argument when the colour is outside (0, 1) or l_d <= 0.
ReducedCoefficients coefficients_from_diffuse_colour(double diffuse_reflectance,
                                                     double diffuse_mean_free_path_mm, double eta);

}  // namespace lucent::materials
