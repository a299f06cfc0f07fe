// Fresnel terms at a smooth dielectric boundary, templated on the scalar type.
#pragma once

#include <algorithm>
#include <cmath>

namespace lucent::materials {

/// Exact unpolarised Fresnel reflectance for light arriving at cos_i (cosine to the normal on the
/// incident side) at an interface with relative index eta = n_transmitted / n_incident.
/// Total internal reflection (possible for eta < 1) gives 1.
template <typename T>
T fresnel_reflectance(T cos_i, T eta) {
  using std::abs;
  using std::sqrt;
  cos_i = abs(cos_i);
  if (cos_i > T(1)) cos_i = T(1);
  const T sin2_t = (T(1) - cos_i * cos_i) / (eta * eta);
  if (!(sin2_t < T(1))) return T(1);
  const T cos_t = sqrt(T(1) - sin2_t);
  const T r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const T r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return T(0.5) * (r_s * r_s + r_p * r_p);
}

/// 1 - fresnel_reflectance: transmittance of the interface (energy, not radiance).
template <typename T>
T fresnel_transmittance(T cos_i, T eta) {
  return T(1) - fresnel_reflectance(cos_i, eta);
}

/// Diffuse (hemispherical, cosine-weighted) Fresnel reflectance seen from inside a medium of
/// relative index eta. eta >= 1: Jensen et al. 2001's fit (seed 004 Table 1; the thesis, seed 003,
/// prints 0.0036 for the last coefficient, 0.0636 is right). eta < 1: Egan and Hilgeman's fit for
/// that range, as used by the same literature; the two meet at eta = 1 within 2e-4.
template <typename T>
T diffuse_fresnel_reflectance(T eta) {
  if (eta < T(1)) {
    const T inv = T(1) / eta;
    return T(-0.4399) + T(0.7099) * inv - T(0.3319) * inv * inv + T(0.0636) * inv * inv * inv;
  }
  return T(-1.440) / (eta * eta) + T(0.710) / eta + T(0.668) + T(0.0636) * eta;
}

/// First Fresnel moment C1(eta) = integral of F_r sin(theta) cos(theta) dtheta over the hemisphere,
/// F_r seen from inside the medium. Polynomial fits of d'Eon and Irving as given in seed 003
/// §3.4.8.
template <typename T>
T fresnel_moment_C1(T n) {
  if (n > T(1)) {
    return (T(-9.23372) +
            n * (T(22.2272) +
                 n * (T(-20.9292) + n * (T(10.2291) + n * (T(-2.54396) + n * T(0.254913)))))) /
           T(2);
  }
  return (T(0.919317) +
          n * (T(-3.4793) +
               n * (T(6.75335) + n * (T(-7.80989) + n * (T(4.98554) + n * T(-1.36881)))))) /
         T(2);
}

/// Second Fresnel moment C2(eta) = integral of F_r sin(theta) cos^2(theta) dtheta (one fit for all
/// n).
template <typename T>
T fresnel_moment_C2(T n) {
  const T inv = T(1) / n;
  return (T(-1641.1) +
          n * (T(1213.67) +
               n * (T(-568.556) + n * (T(164.798) + n * (T(-27.0181) + n * T(1.91826))))) +
          inv * (T(1376.53) + inv * (T(-656.175) + inv * T(135.926)))) /
         T(3);
}

/// C_phi(eta) = (1 - 2 C1(eta)) / 4: fraction of fluence crossing the boundary.
template <typename T>
T C_phi(T eta) {
  return (T(1) - T(2) * fresnel_moment_C1(eta)) / T(4);
}

/// C_E(eta) = (1 - 3 C2(eta)) / 2: fraction of flux crossing the boundary.
template <typename T>
T C_E(T eta) {
  return (T(1) - T(3) * fresnel_moment_C2(eta)) / T(2);
}

}  // namespace lucent::materials
