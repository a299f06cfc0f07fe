// How multiple scattering depends on the angles of incidence and exit beyond the Fresnel
// transmittances (lucent; docs/DESIGN.md §4.3). The radial BSSRDFs (tabulated, dipole) treat light
// entering at any angle as light entering along the normal and let it leave with the angular shape
// F_t(cos_o); on a plane the transport tables are exact only along the normal. For a semi-infinite
// medium of isotropic scatterers at eta 1, Chandrasekhar's reflection function is exact:
//   f(mu_i, mu_o) = omega / (4 pi) H(mu_i) H(mu_o) / (mu_i + mu_o),
// of which the single-scattering part is omega / (4 pi) / (mu_i + mu_o); the multiple-scattering
// BRDF relative to its value along the normal is
//   K(mu_i, mu_o) = [(H(mu_i) H(mu_o) - 1) / (mu_i + mu_o)] / [(H(1)^2 - 1) / 2],
// here with the reduced albedo alpha' (similarity) and the refracted (inside) cosines. The
// techniques take it as a product of one factor per side, k(mu) = sqrt(K(mu, mu)): exact where
// incidence and exit make the same angle with the normal (the slab lit and seen at 60 degrees),
// within 4-5% of K where one of them is the normal at 60 degrees, 6-9% RMS over the hemispheres.
// Measured against the path tracer's multiple scattering on a plane (the path tracer's image less
// the closed-form single scattering, tests/render/angular_test.cpp): at eta 1, 60/60, the
// product is within 2%; at eta 1.3 the inside cosines leave a residual of 3-7% at 60-75 degrees.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"

namespace lucent::materials {

/// Whether the angular factor applies to `model`: the radial models (tabulated, dipole); the
/// directional dipole has its own dependence on the incidence.
inline bool angular_factor_applies(DiffusionModel model) {
  return model != DiffusionModel::kDirectionalDipole;
}

/// Where an oblique beam's multiple scattering is centred (docs/DESIGN.md §4.3). On a plane, the
/// exitance of light entering at the outside direction w (unit, toward the light) is centred
/// sin(theta_t) / sigma_t' from the entry point, along the refracted beam's direction within the
/// surface: where its first collisions are (Wang and Jacques 1995, "Use of a laser beam with an
/// oblique angle of incidence to measure the reduced scattering coefficient of a turbid medium";
/// measured by Monte Carlo: 1.06-1.11 of it at alpha' 0.9965 and eta 1, 0.94-0.98 at eta 1.3,
/// 0.72-1.0 at alpha' 0.7-0.9). The radial models take the entry point so displaced as the source
/// (and, by reciprocity, the exit point displaced along the view's reversed refracted direction).
/// On a plane under uniform light that changes nothing; on a sphere it moves the light entering
/// near the terminator toward the far side, where the truth has it (at eta 1, where the beam is not
/// bent toward the normal, a radial profile at the entry point put 9-15% too much light on the lit
/// side of 10-30 mm spheres). Returns the displacement per unit of 1 / sigma_t' (length
/// sin(theta_t) <= 1 / eta): the tangential part of refract(-w, n) for eta = n_inside / n_outside;
/// zero for w along n.
template <typename Vec3>
Vec3 oblique_displacement(const Vec3& w, const Vec3& n, double eta) {
  return (w.dot(n) * n - w) / eta;
}

/// The modified Bessel function I_0(a) for |a| <= 2 (eight terms of its power series: 1e-10
/// relative; the skew's a is at most 1.6). The GLSL twin sums the same terms.
inline double bessel_i0(double a) {
  const double q = 0.25 * a * a;
  double term = 1, sum = 1;
  for (int k = 1; k <= 8; ++k) {
    term *= q / double(k * k);
    sum += term;
  }
  return sum;
}

/// The oblique beam's skew of a radial profile: light entering at x_i and leaving at x_o
/// (x = x_o - x_i, r = |x| mm) with `shift` = oblique_displacement(w_i, n_i) -
/// oblique_displacement(w_o, n_o) takes
///   R(r) exp(a x^ . shift^) / I_0(a),  a = |shift| min(kObliqueSkewNear, l (sigma_tr + 3 / r)),
/// l = 1 / sigma_t' (mm). Each ring about the entry keeps its total (a plane under uniform light is
/// unchanged, and so is the profile's peak at the entry); its mean cos(phi) toward the beam is
/// I_1 / I_0 (a). Far from the entry that is the diffusion profile (-d ln R / dr ~ sigma_tr + 3 /
/// r) displaced by the oblique beam's centroid shift l sin(theta_t) (Wang and Jacques 1995, "Use of
/// a laser beam with an oblique angle of incidence to measure the reduced scattering coefficient of
/// a turbid medium"); near it, light scattered a few times, the skew saturates. Measured by Monte
/// Carlo on a plane (the ring's mean cos(phi) over sin(theta_t), at 30-80 degrees, r 0.05-16 mean
/// free paths): alpha' 0.9965 0.25-0.5 within 3 mean free paths falling to 0.15-0.23 at 16, alpha'
/// 0.9 0.26-0.6 throughout, eta 1.3 0.85x eta 1's; the form gives 0.38 near, 0.16-0.21 (0.9965)
/// and 0.4-0.55 (0.9) far. The centroid's shift: 1.06-1.11 l sin(theta_t) at eta 1, 0.94-0.98 at
/// 1.3 (alpha' 0.9965). By reciprocity the view's refracted direction skews the exit side the
/// other way. A displacement of the whole profile instead moves its peak off the entry: neither
/// what the light does nor what a sampler drawing around the entry can find (a plane lit at 60
/// degrees came out 1-3.5% dark at 256 probes).
inline constexpr double kObliqueSkewNear = 0.8;

template <typename Vec3>
double oblique_skew(const Vec3& x, const Vec3& shift, double mean_free_path, double sigma_tr) {
  const double r = x.norm(), s = shift.norm();
  if (!(r > 0) || !(s > 0)) return 1;
  const double a = s * std::min(kObliqueSkewNear, mean_free_path * (sigma_tr + 3 / r));
  return std::exp(a * x.dot(shift) / (r * s)) / bessel_i0(a);
}

/// Chandrasekhar's H-function of isotropic scattering with single-scattering albedo omega in
/// [0, 1], from 1/H(mu) = sqrt(1 - omega) + (omega / 2) int_0^1 mu' H(mu') / (mu + mu') dmu' on 48
/// Gauss-Legendre nodes (a damped iteration to 1e-13; H(1) is 1.8500985 at omega 0.9, 2.90781 at 1).
class HFunction {
 public:
  explicit HFunction(double omega);
  double operator()(double mu) const;

 private:
  double omega_;
  std::vector<double> mu_, weight_, h_;
};

/// k(mu) per channel of a material, tabulated over the outside cosine (kAngularNodes nodes on
/// [0, 1], linear between them; the GLSL twin uploads the same nodes). k(1) = 1.
class AngularFactor {
 public:
  static constexpr int kNodes = 33;
  explicit AngularFactor(const Material& material);
  /// k for channel c at the outside cosine cos_theta (clamped to [0, 1]).
  double operator()(int c, double cos_theta) const {
    const double x = std::fmin(std::fmax(cos_theta, 0.0), 1.0) * (kNodes - 1);
    const int i = std::min(int(x), kNodes - 2);
    const double t = x - i;
    const auto& row = nodes_[std::size_t(c)];
    return row[std::size_t(i)] * (1 - t) + row[std::size_t(i) + 1] * t;
  }
  const std::array<double, kNodes>& nodes(int c) const { return nodes_[std::size_t(c)]; }
  /// The exact two-sided K(mu_i, mu_o) for channel c at outside cosines (for tests and reports).
  double two_sided(int c, double cos_i, double cos_o) const;

 private:
  double eta_ = 1;
  std::array<double, 3> albedo_{};
  std::array<std::array<double, kNodes>, 3> nodes_{};
};

}  // namespace lucent::materials
