// Optical properties of one colour channel and the coefficients diffusion theory derives from them.
// Everything is templated on the scalar type so the same code runs in double (reference), float
// (the shaders' twin) and ceres::Jet (fitting). All lengths in mm, all coefficients in mm^-1.
#pragma once

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <type_traits>

#include "lucent/materials/fresnel.h"

namespace lucent::materials {

/// One channel of a homogeneous medium.
template <typename T>
struct Medium {
  T sigma_a{0};  ///< absorption coefficient, mm^-1
  T sigma_s{0};  ///< scattering coefficient (unreduced), mm^-1
  T g{0};        ///< Henyey-Greenstein mean cosine; 0 when only sigma_s' is known
  T eta{1};      ///< relative index of refraction, n_sample / n_outside

  /// A medium known only through its reduced scattering coefficient: treated as isotropic (g = 0),
  /// so sigma_s = sigma_s' and sigma_t = sigma_t'.
  static Medium from_reduced(T sigma_a, T sigma_s_reduced, T eta) {
    return Medium{sigma_a, sigma_s_reduced, T(0), eta};
  }

  std::string to_string() const;
};

/// The Henyey-Greenstein phase function: density per steradian of turning by cos_theta, mean
/// cosine g (|g| < 1).
inline double henyey_greenstein(double g, double cos_theta) {
  const double d = 1 + g * g - 2 * g * cos_theta;
  return (1 - g * g) / (4 * std::numbers::pi * d * std::sqrt(d));
}

/// Every coefficient of docs/DESIGN.md §4 for one channel. Names follow the papers.
template <typename T>
struct DiffusionCoefficients {
  T eta;
  T sigma_s_reduced;  ///< sigma_s' = sigma_s (1 - g), mm^-1
  T sigma_t_reduced;  ///< sigma_t' = sigma_a + sigma_s', mm^-1
  T sigma_t;          ///< sigma_t = sigma_a + sigma_s, mm^-1
  T alpha_prime;      ///< reduced albedo sigma_s' / sigma_t' (0 for a medium that does not scatter)
  T D;                ///< diffusion coefficient 1 / (3 sigma_t'), mm (not Grosjean's form)
  T sigma_tr;         ///< effective transport coefficient sqrt(sigma_a / D), mm^-1
  T z_r;              ///< standard dipole: real source depth 1 / sigma_t', mm
  T F_dr;             ///< diffuse Fresnel reflectance inside the medium (Jensen et al. 2001 fit)
  T A_dipole;         ///< standard dipole boundary term (1 + F_dr) / (1 - F_dr)
  T z_v;              ///< standard dipole: virtual source height z_r + 4 A D, mm
  T d_e;              ///< directional dipole extrapolation distance 2.131 D / sqrt(alpha'), mm
  T C_phi;            ///< C_phi(eta)
  T C_E;              ///< C_E(eta)
  T A_ddipole;        ///< directional dipole boundary term (1 - C_E) / (2 C_phi)
  T normalisation;    ///< directional dipole normalisation 1 / (4 C_phi(1 / eta))

  /// True when the channel scatters at all; every model returns 0 otherwise.
  bool scatters() const { return alpha_prime > T(0); }

  std::string to_string() const;
};

template <typename T>
DiffusionCoefficients<T> derive_coefficients(const Medium<T>& m) {
  using std::sqrt;
  if constexpr (std::is_same_v<T, float>) {
    // The Fresnel-moment fits sum terms of size 1e3 to results of size 0.1: in float they keep only
    // four digits. Like the shaders, which get these constants from the CPU, float models derive
    // them in double and round once.
    const auto d = derive_coefficients(Medium<double>{m.sigma_a, m.sigma_s, m.g, m.eta});
    return DiffusionCoefficients<float>{float(d.eta),
                                        float(d.sigma_s_reduced),
                                        float(d.sigma_t_reduced),
                                        float(d.sigma_t),
                                        float(d.alpha_prime),
                                        float(d.D),
                                        float(d.sigma_tr),
                                        float(d.z_r),
                                        float(d.F_dr),
                                        float(d.A_dipole),
                                        float(d.z_v),
                                        float(d.d_e),
                                        float(d.C_phi),
                                        float(d.C_E),
                                        float(d.A_ddipole),
                                        float(d.normalisation)};
  }
  DiffusionCoefficients<T> c;
  c.eta = m.eta;
  c.sigma_s_reduced = m.sigma_s * (T(1) - m.g);
  c.sigma_t_reduced = m.sigma_a + c.sigma_s_reduced;
  c.sigma_t = m.sigma_a + m.sigma_s;
  // A medium that neither scatters nor absorbs has no diffusion length at all; keep every derived
  // value finite (zeros and infinities are confined to D, z_r, d_e, which no model reads then).
  const bool empty = !(c.sigma_t_reduced > T(0));
  c.alpha_prime = empty ? T(0) : c.sigma_s_reduced / c.sigma_t_reduced;
  c.D = empty ? T(0) : T(1) / (T(3) * c.sigma_t_reduced);
  // sigma_tr = sqrt(sigma_a / D) = sqrt(3 sigma_a sigma_t'); written without the division so that
  // sigma_a = 0 gives exactly 0 and Jets get a finite derivative for sigma_a > 0.
  const T tr2 = T(3) * m.sigma_a * c.sigma_t_reduced;
  c.sigma_tr = tr2 > T(0) ? sqrt(tr2) : T(0);
  c.z_r = empty ? T(0) : T(1) / c.sigma_t_reduced;
  c.F_dr = diffuse_fresnel_reflectance(m.eta);
  c.A_dipole = (T(1) + c.F_dr) / (T(1) - c.F_dr);
  c.z_v = c.z_r + T(4) * c.A_dipole * c.D;
  c.d_e = c.scatters() ? T(2.131) * c.D / sqrt(c.alpha_prime) : T(0);
  c.C_phi = C_phi(m.eta);
  c.C_E = C_E(m.eta);
  c.A_ddipole = (T(1) - c.C_E) / (T(2) * c.C_phi);
  c.normalisation = T(1) / (T(4) * C_phi(T(1) / m.eta));
  return c;
}

namespace detail {
template <typename T>
double scalar_value(const T& x) {
  if constexpr (requires { x.a; }) {
    return static_cast<double>(x.a);  // ceres::Jet
  } else {
    return static_cast<double>(x);
  }
}
}  // namespace detail

template <typename T>
std::string Medium<T>::to_string() const {
  std::ostringstream s;
  s.precision(6);
  s << "Medium{sigma_a=" << detail::scalar_value(sigma_a)
    << "/mm, sigma_s=" << detail::scalar_value(sigma_s) << "/mm, g=" << detail::scalar_value(g)
    << ", eta=" << detail::scalar_value(eta) << "}";
  return s.str();
}

template <typename T>
std::string DiffusionCoefficients<T>::to_string() const {
  using detail::scalar_value;
  std::ostringstream s;
  s.precision(6);
  s << "DiffusionCoefficients{eta=" << scalar_value(eta)
    << ", sigma_s'=" << scalar_value(sigma_s_reduced)
    << "/mm, sigma_t'=" << scalar_value(sigma_t_reduced) << "/mm, sigma_t=" << scalar_value(sigma_t)
    << "/mm, alpha'=" << scalar_value(alpha_prime) << ", D=" << scalar_value(D)
    << "mm, sigma_tr=" << scalar_value(sigma_tr) << "/mm, z_r=" << scalar_value(z_r)
    << "mm, z_v=" << scalar_value(z_v) << "mm, F_dr=" << scalar_value(F_dr)
    << ", A=" << scalar_value(A_dipole) << ", d_e=" << scalar_value(d_e)
    << "mm, C_phi=" << scalar_value(C_phi) << ", C_E=" << scalar_value(C_E)
    << ", A_dd=" << scalar_value(A_ddipole) << "}";
  return s.str();
}

}  // namespace lucent::materials
