// lucent GLSL 1: the standard dipole of Jensen et al. 2001 (Mertens et al. Table 1, Dal Corso 2014 §3.4.7,
// docs/DESIGN.md §4), twin of StandardDipole<float> in materials/include/lucent/materials/dipole.h: the
// float branch of its source term (one exponential of a sum of logarithms, so that neither
// e^(-sigma_tr d) nor 1/d^3 under- or overflows alone). tests/render/glsl_twin_test.cpp holds the
// two together. Lengths in mm, coefficients in mm^-1.
#ifndef LUCENT_BSSRDF_DIPOLE_GLSL
#define LUCENT_BSSRDF_DIPOLE_GLSL

#include "math.glsl"

// One channel's derived coefficients, from materials::derive_coefficients in double. Member order
// is the std430 layout of render/gl/gl_bssrdf.h.
struct DipoleChannel {
  float alpha_prime;  // reduced albedo; 0: the channel does not scatter and R_d = 0
  float sigma_tr;     // sqrt(3 sigma_a sigma_t'), mm^-1
  float z_r;          // real source depth 1 / sigma_t', mm
  float z_v;          // virtual source height z_r + 4 A D, mm
};

// z (1 + sigma_tr d) e^(-sigma_tr d) / d^3, d = sqrt(r^2 + z^2).
float dipole_source_term(DipoleChannel c, float z, float r2) {
  float d2 = r2 + z * z;
  float d = sqrt(d2);
  float s = c.sigma_tr * d;
  return exp(log(z) + lucent_log1p(s) - s - 1.5 * log(d2));
}

// Radially symmetric diffuse reflectance R_d(r) per mm^2 for unit incident flux, r in mm.
float dipole_R_d(DipoleChannel c, float r) {
  if (!(c.alpha_prime > 0.0)) return 0.0;
  float r2 = r * r;
  return c.alpha_prime / (4.0 * kPi) *
         (dipole_source_term(c, c.z_r, r2) + dipole_source_term(c, c.z_v, r2));
}

// The BSSRDF without the two Fresnel transmittances: S_d = R_d / pi, per mm^2 per sr.
float dipole_S_d(DipoleChannel c, float r) { return dipole_R_d(c, r) / kPi; }

vec3 dipole_S_d_rgb(DipoleChannel c[3], float r) {
  return vec3(dipole_S_d(c[0], r), dipole_S_d(c[1], r), dipole_S_d(c[2], r));
}

#endif
