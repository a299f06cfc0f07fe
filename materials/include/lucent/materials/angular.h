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
