// The standard dipole of Jensen et al. 2001 (Mertens et al. Table 1, Dal Corso 2014 §3.4.7).
#pragma once

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <type_traits>

#include "lucent/materials/medium.h"

namespace lucent::materials {

/// Total diffuse reflectance of the standard dipole over the whole plane, a closed form in the
/// reduced albedo alpha' and the boundary term A (docs/DESIGN.md §4): R_tot = alpha'/2 (1 +
/// e^(-(4/3) A sqrt(3 (1 - alpha')))) e^(-sqrt(3 (1 - alpha'))).
template <typename T>
T dipole_total_reflectance(T alpha_prime, T A) {
  using std::exp;
  using std::sqrt;
  const T one_minus = T(1) - alpha_prime;
  const T s = one_minus > T(0) ? sqrt(T(3) * one_minus) : T(0);
  return alpha_prime / T(2) * (T(1) + exp(T(-4) / T(3) * A * s)) * exp(-s);
}

template <typename T>
class StandardDipole {
 public:
  explicit StandardDipole(const Medium<T>& medium)
      : medium_(medium), c_(derive_coefficients(medium)) {}

  /// Radially symmetric diffuse reflectance R_d(r) per mm^2 for unit incident flux, r in mm.
  T R_d(T r_mm) const {
    if (!c_.scatters()) return T(0);
    const T r2 = r_mm * r_mm;
    return c_.alpha_prime / T(4 * std::numbers::pi) *
           (source_term(c_.z_r, r2) + source_term(c_.z_v, r2));
  }

  /// Diffusion BSSRDF without the two Fresnel transmittances: S_d = R_d / pi, per mm^2 per sr.
  T S_d(T r_mm) const { return R_d(r_mm) / T(std::numbers::pi); }

  /// Closed-form integral of R_d over the plane.
  T total_diffuse_reflectance() const {
    return dipole_total_reflectance(c_.alpha_prime, c_.A_dipole);
  }

  const Medium<T>& medium() const { return medium_; }
  const DiffusionCoefficients<T>& coefficients() const { return c_; }

  std::string to_string() const { return "StandardDipole{" + c_.to_string() + "}"; }

 private:
  // z (1 + sigma_tr d) e^(-sigma_tr d) / d^3 with d = sqrt(r^2 + z^2). In float it is evaluated as
  // one exponential of a sum of logarithms so that neither e^(-sigma_tr d) nor 1/d^3 under- or
  // overflows on its own (float reaches 1e-38 in e^(-x) already at x = 87, long before the product
  // is negligible). In double (and Jets of double) the direct form is safe: e^(-x) underflows only
  // past x = 745, where z / d^3 <= sigma_t'^2 cannot lift the product above 1e-300; and it is three
  // times cheaper, which fitting feels.
  T source_term(T z, T r2) const {
    using std::exp;
    using std::log;
    using std::log1p;
    using std::sqrt;
    const T d2 = r2 + z * z;
    const T d = sqrt(d2);
    const T s = c_.sigma_tr * d;
    if constexpr (std::is_same_v<T, float>) {
      return exp(log(z) + log1p(s) - s - T(1.5) * log(d2));
    } else {
      return z * (T(1) + s) * exp(-s) / (d2 * d);
    }
  }

  Medium<T> medium_;
  DiffusionCoefficients<T> c_;
};

}  // namespace lucent::materials
