// lucent GLSL 1: twin of materials/include/lucent/materials/specular.h (ggx_reflection): radiance
// reflected toward the eye per unit irradiance from a light, GGX microfacets on a dielectric.
#ifndef LUCENT_SPECULAR_GLSL
#define LUCENT_SPECULAR_GLSL

#include "math.glsl"
#include "fresnel.glsl"

float ggx_G1(float c, float a2) { return 2.0 * c / (c + sqrt(a2 + (1.0 - a2) * c * c)); }

float ggx_reflection(float cos_i, float cos_o, float cos_h, float cos_d, float alpha, float eta) {
  if (!(cos_i > 0.0) || !(cos_o > 0.0) || !(alpha > 0.0)) return 0.0;
  float a2 = alpha * alpha;
  float t = cos_h * cos_h * (a2 - 1.0) + 1.0;
  float D = a2 / (kPi * t * t);
  return fresnel_reflectance(cos_d, eta) * D * ggx_G1(cos_i, a2) * ggx_G1(cos_o, a2) /
         (4.0 * cos_o);
}

#endif
