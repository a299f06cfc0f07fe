// lucent GLSL 1: twin of render/core/single_scattering.h (single_scattering_radiance): Jensen et al.
// 2001's single-scattering term by the midpoints of `steps` strata of u = 1 - e^(-sigma_t s) along
// the refracted view ray, per channel. The including shader defines single_scattering_entry (the
// light's entry point from x toward w: the straight line's distance to the surface, mm, and the
// outward normal there; false when there is none), declared here.
#ifndef LUCENT_SINGLE_SCATTERING_GLSL
#define LUCENT_SINGLE_SCATTERING_GLSL

#include "math.glsl"
#include "fresnel.glsl"

bool single_scattering_entry(int light, vec3 x, vec3 w, out float distance_mm, out vec3 normal);

struct SingleMedium {
  vec3 sigma_s;  // mm^-1
  vec3 sigma_t;  // mm^-1
  vec3 g;        // Henyey-Greenstein
  float eta;
};

float henyey_greenstein(float g, float cos_theta) {
  float d = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * kPi * d * sqrt(d));
}

// light_position: w 1 a point (xyz mm, radiance its intensity), w 0 a direction toward the light
// (radiance the irradiance on a surface facing it).
vec3 single_scattering_radiance(SingleMedium m, vec3 x_o, vec3 n_o, vec3 w_o, int light,
                                vec4 light_position, vec3 radiance, int steps) {
  vec3 L = vec3(0.0);
  float cos_o = dot(n_o, w_o);
  if (!(cos_o > 0.0)) return L;
  float eta = m.eta;
  float cos_to = sqrt(max(0.0, 1.0 - (1.0 - cos_o * cos_o) / (eta * eta)));
  vec3 t = -w_o / eta + (cos_o / eta - cos_to) * n_o;
  float leaving = fresnel_transmittance(cos_o, eta) / (eta * eta);
  bool is_point = light_position.w > 0.5;
  for (int c = 0; c < 3; ++c) {
    float sigma_t = m.sigma_t[c];
    if (!(sigma_t > 0.0)) continue;
    float sum = 0.0;
    for (int k = 0; k < steps; ++k) {
      float u = (float(k) + 0.5) / float(steps);
      float s = -lucent_log1p(-u) / sigma_t;
      vec3 x = x_o + s * t;
      vec3 w = is_point ? normalize(light_position.xyz - x) : light_position.xyz;
      float distance_mm;
      vec3 n_i;
      if (!single_scattering_entry(light, x, w, distance_mm, n_i) || !(distance_mm >= 0.0)) continue;
      float cos_i = dot(w, n_i);
      if (!(cos_i > 0.0)) continue;
      float cos_ti = sqrt(max(0.0, 1.0 - (1.0 - cos_i * cos_i) / (eta * eta)));
      float s_in = distance_mm * cos_i / cos_ti;
      float E = radiance[c];
      if (is_point) {
        vec3 d = light_position.xyz - (x + distance_mm * w);
        E /= max(dot(d, d), 1e-12);
      }
      float E_in = E * fresnel_transmittance(cos_i, eta) * cos_i / cos_ti;
      vec3 d_in = -w / eta + (cos_i / eta - cos_ti) * n_i;
      sum += m.sigma_s[c] * henyey_greenstein(m.g[c], -dot(d_in, t)) * E_in * exp(-sigma_t * s_in);
    }
    L[c] = leaving * sum / (float(steps) * sigma_t);
  }
  return L;
}

#endif
