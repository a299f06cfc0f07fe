// lucent GLSL 1: twin of materials/include/lucent/materials/fresnel.h (fresnel_reflectance,
// fresnel_transmittance). The Fresnel-moment fits (C_phi, C_E) are not here: the CPU evaluates them
// in double and passes the results as uniforms (see derive_coefficients' float branch).
#ifndef LUCENT_FRESNEL_GLSL
#define LUCENT_FRESNEL_GLSL

// Exact unpolarised reflectance for light arriving at cos_i at an interface of relative index
// eta = n_transmitted / n_incident; total internal reflection gives 1.
float fresnel_reflectance(float cos_i, float eta) {
  cos_i = min(abs(cos_i), 1.0);
  float sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (!(sin2_t < 1.0)) return 1.0;
  float cos_t = sqrt(1.0 - sin2_t);
  float r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  float r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (r_s * r_s + r_p * r_p);
}

float fresnel_transmittance(float cos_i, float eta) { return 1.0 - fresnel_reflectance(cos_i, eta); }

#endif
