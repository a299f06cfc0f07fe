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
/// relative index eta. eta >= 1: Jensen et al. 2001's fit (Mertens et al. Table 1; the thesis, Dal
/// Corso 2014, prints 0.0036 for the last coefficient, 0.0636 is right). eta < 1: Egan and
/// Hilgeman's fit for that range, as used by the same literature; the two meet at eta = 1 within
/// 2e-4.
template <typename T>
T diffuse_fresnel_reflectance(T eta) {
  if (eta < T(1)) {
    const T inv = T(1) / eta;
    return T(-0.4399) + T(0.7099) * inv - T(0.3319) * inv * inv + T(0.0636) * inv * inv * inv;
  }
  return T(-1.440) / (eta * eta) + T(0.710) / eta + T(0.668) + T(0.0636) * eta;
}

/// First Fresnel moment C1(eta) = integral of F_r sin(theta) cos(theta) dtheta over the hemisphere,
/// F_r seen from inside the medium. Polynomial fits of d'Eon and Irving as given in Dal Corso 2014
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

/// Second Fresnel moment C2(eta) = integral of F_r sin(theta) cos^2(theta) dtheta, F_r seen from
/// inside. eta >= 1: d'Eon and Irving's fit as given in Dal Corso 2014 §3.4.8 (within 0.6% in C_E
/// of the quadrature up to eta 2, 4% at 2.5). Their fit has one branch for every eta, but below 1
/// it is not the moment at all (C_E(0.8) = 0.12 where the quadrature gives 0.486, C_E(0.75) < 0):
/// there the integrand has no total internal reflection and is smooth in mu = cos(theta), so a
/// 16-node Gauss-Legendre rule of the definition, integral_0^1 F_r(mu, 1 / eta) mu^2 dmu, is exact
/// to 1e-10 (tests/materials/fresnel_test.cpp holds both branches against an adaptive quadrature).
template <typename T>
T fresnel_moment_C2(T n) {
  if (n < T(1)) {
    // Nodes x_k in (0, 1) of the 16-point rule on [-1, 1] (symmetric) and their weights.
    static constexpr double kNodes[8][2] = {
        {0.98940093499164994, 0.027152459411754058}, {0.9445750230732326, 0.062253523938647776},
        {0.86563120238783176, 0.095158511682492897}, {0.755404408355003, 0.12462897125553395},
        {0.61787624440264377, 0.14959598881657682},  {0.45801677765722737, 0.16915651939500256},
        {0.28160355077925892, 0.18260341504492361},  {0.095012509837637441, 0.18945061045506847}};
    const T inv = T(1) / n;
    T sum = T(0);
    for (const auto& [x, w] : kNodes) {
      for (double mu : {0.5 * (1 + x), 0.5 * (1 - x)}) {
        sum += T(0.5 * w * mu * mu) * fresnel_reflectance(T(mu), inv);
      }
    }
    return sum;
  }
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
