// The surface's own reflection of a light (the specular lobe every light gets, `--roughness`): a
// dielectric interface with GGX microfacets (Walter, Marschner, Li and Torrance 2007), the exact
// unpolarised Fresnel reflectance at the microfacet, Smith's separable shadowing. Templated on the
// scalar; render/gl/shaders/specular.glsl is its GLSL twin.
#pragma once

#include <cmath>
#include <numbers>

#include "lucent/materials/fresnel.h"

namespace lucent::materials {

/// Radiance reflected toward the eye per unit irradiance arriving from the light (irradiance on a
/// surface facing it): F(eta, h . w_i) D(h) G1(w_i) G1(w_o) / (4 n . w_o), the BRDF times
/// n . w_i. cos_i = n . w_i, cos_o = n . w_o, cos_h = n . h, cos_d = h . w_i with h the unit half
/// vector; alpha the GGX width (0.02 polished .. 0.5 matte). 0 where either side is below the
/// surface, and for alpha = 0 (a smooth interface reflects a point light into one direction only:
/// no highlight from it, only the environment's mirror image).
template <typename T>
T ggx_reflection(T cos_i, T cos_o, T cos_h, T cos_d, T alpha, T eta) {
  using std::sqrt;
  if (!(cos_i > T(0)) || !(cos_o > T(0)) || !(alpha > T(0))) return T(0);
  const T a2 = alpha * alpha;
  const T t = cos_h * cos_h * (a2 - T(1)) + T(1);
  const T D = a2 / (T(std::numbers::pi) * t * t);
  const auto G1 = [&](T c) { return T(2) * c / (c + sqrt(a2 + (T(1) - a2) * c * c)); };
  const T F = fresnel_reflectance(cos_d, eta);
  return F * D * G1(cos_i) * G1(cos_o) / (T(4) * cos_o);
}

}  // namespace lucent::materials
