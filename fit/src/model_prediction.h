// The predicted measurement pi L / P of a capture, per channel, for a bin or pixel footprint: the
// BSSRDF with both Fresnel transmittances (DESIGN §6), averaged over the footprint by
// Gauss-Legendre quadrature. Templated for ceres::Jet.
#pragma once

#include <array>
#include <cmath>
#include <numbers>

#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"

namespace lucent::fit::detail {

/// Gauss-Legendre nodes and weights on [0, 1] for orders 1..8.
struct GaussLegendre {
  std::array<double, 8> node{}, weight{};
  int order = 1;
};
GaussLegendre gauss_legendre(int order);

/// Geometry shared by every sample of one capture.
struct CaptureGeometry {
  double cos_incidence = 1;            ///< cos of the beam's polar angle
  double cos_view = 1;                 ///< cos of the camera's polar angle
  std::array<double, 3> w_i{0, 0, 1};  ///< unit, from the entry point toward the light
  /// The data are exitance per unit power entering the sample (Monte Carlo tallies, CSV), not a
  /// camera's radiance per unit incident power.
  bool exitance = false;
};

/// What multiplies the model's R_d (dipole) or pi S_d (ddipole) to give the measured quantity: both
/// Fresnel transmittances for a camera (pi L / P); for exitance per unit power entering, nothing
/// for the dipole (R_d is an exitance) and the outgoing hemispherical transmittance for the
/// ddipole, pi S_d integrated against F_t cos over the hemisphere: eta^2 (1 - F_dr(eta))
/// (transmittance from inside is 1 - F_dr, from outside eta^2 times that).
template <typename T>
T fresnel_factor(const CaptureGeometry& g, const T& eta, bool directional) {
  using materials::fresnel_transmittance;
  if (g.exitance)
    return directional ? eta * eta * (T(1) - materials::diffuse_fresnel_reflectance(eta)) : T(1);
  return fresnel_transmittance(T(g.cos_incidence), eta) * fresnel_transmittance(T(g.cos_view), eta);
}

/// Standard dipole: mean of R_d over the annulus [r0, r1] (or R_d(r) when r0 == r1), per mm^2.
template <typename T>
T dipole_annulus(const materials::StandardDipole<T>& dipole, double r, double r0, double r1,
                 const GaussLegendre& gl) {
  if (!(r1 > r0)) return dipole.R_d(T(r));
  // Average over area: integral of 2 pi r R_d dr / (pi (r1^2 - r0^2)); nodes in r^2 so that the
  // weight is uniform in area.
  T sum(0);
  for (int k = 0; k < gl.order; ++k) {
    const double r_k = std::sqrt(r0 * r0 + gl.node[k] * (r1 * r1 - r0 * r0));
    sum += gl.weight[k] * dipole.R_d(T(r_k));
  }
  return sum;
}

/// Directional dipole at normal incidence on a plane: pi S_d averaged over the annulus.
template <typename T>
T ddipole_annulus(const materials::DirectionalDipole<T>& dd, double r, double r0, double r1,
                  const GaussLegendre& gl) {
  const materials::Vec3<T> up(T(0), T(0), T(1));
  const auto at = [&](double rr) {
    return T(std::numbers::pi) *
           dd.S_d(materials::Vec3<T>::Zero(), up, up, materials::Vec3<T>(T(rr), T(0), T(0)), up);
  };
  if (!(r1 > r0)) return at(r);
  T sum(0);
  for (int k = 0; k < gl.order; ++k) {
    sum += gl.weight[k] * at(std::sqrt(r0 * r0 + gl.node[k] * (r1 * r1 - r0 * r0)));
  }
  return sum;
}

/// Directional dipole for a square pixel centred at (x, y) of side `pixel` (0: the point), light
/// from w_i: pi S_d averaged over the footprint.
template <typename T>
T ddipole_pixel(const materials::DirectionalDipole<T>& dd, const CaptureGeometry& g, double x,
                double y, double pixel, const GaussLegendre& gl) {
  const materials::Vec3<T> up(T(0), T(0), T(1));
  const materials::Vec3<T> w_i(T(g.w_i[0]), T(g.w_i[1]), T(g.w_i[2]));
  const auto at = [&](double px, double py) {
    return T(std::numbers::pi) *
           dd.S_d(materials::Vec3<T>::Zero(), up, w_i, materials::Vec3<T>(T(px), T(py), T(0)), up);
  };
  if (!(pixel > 0)) return at(x, y);
  T sum(0);
  for (int a = 0; a < gl.order; ++a) {
    for (int b = 0; b < gl.order; ++b) {
      sum += gl.weight[a] * gl.weight[b] *
             at(x + (gl.node[a] - 0.5) * pixel, y + (gl.node[b] - 0.5) * pixel);
    }
  }
  return sum;
}

/// Standard dipole for a square pixel.
template <typename T>
T dipole_pixel(const materials::StandardDipole<T>& dipole, double x, double y, double pixel,
               const GaussLegendre& gl) {
  if (!(pixel > 0)) return dipole.R_d(T(std::hypot(x, y)));
  T sum(0);
  for (int a = 0; a < gl.order; ++a) {
    for (int b = 0; b < gl.order; ++b) {
      sum +=
          gl.weight[a] * gl.weight[b] *
          dipole.R_d(T(std::hypot(x + (gl.node[a] - 0.5) * pixel, y + (gl.node[b] - 0.5) * pixel)));
    }
  }
  return sum;
}

}  // namespace lucent::fit::detail
