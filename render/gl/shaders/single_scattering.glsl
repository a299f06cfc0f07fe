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
  float lo = min(m.sigma_t.x, min(m.sigma_t.y, m.sigma_t.z));
  float hi = max(m.sigma_t.x, max(m.sigma_t.y, m.sigma_t.z));
  bool one_set = lo > 0.0 && hi <= 2.0 * lo;  // kShareRatioWide
  int n = one_set && hi > 1.25 * lo ? (3 * steps + 1) / 2 : steps;  // shared_steps
  for (int group = 0; group < (one_set ? 1 : 3); ++group) {
    float sigma_ref = one_set ? lo : m.sigma_t[group];
    if (!(sigma_ref > 0.0)) continue;
    int first = one_set ? 0 : group, last = one_set ? 2 : group;
    vec3 sum = vec3(0.0);
    for (int k = 0; k < n; ++k) {
      float u = (float(k) + 0.5) / float(n);
      float s = -lucent_log1p(-u) / sigma_ref;
      vec3 x = x_o + s * t;
      vec3 w = is_point ? normalize(light_position.xyz - x) : light_position.xyz;
      float distance_mm;
      vec3 n_i;
      if (!single_scattering_entry(light, x, w, distance_mm, n_i) || !(distance_mm >= 0.0)) continue;
      float cos_i = dot(w, n_i);
      if (!(cos_i > 0.0)) continue;
      float cos_ti = sqrt(max(0.0, 1.0 - (1.0 - cos_i * cos_i) / (eta * eta)));
      float s_in = distance_mm * cos_i / cos_ti;
      float falloff = 1.0;
      if (is_point) {
        vec3 d = light_position.xyz - (x + distance_mm * w);
        falloff = 1.0 / max(dot(d, d), 1e-12);
      }
      float T_in = fresnel_transmittance(cos_i, eta) * cos_i / cos_ti;
      vec3 d_in = -w / eta + (cos_i / eta - cos_ti) * n_i;
      for (int c = first; c <= last; ++c) {
        float sigma_t = m.sigma_t[c];
        sum[c] += m.sigma_s[c] * henyey_greenstein(m.g[c], -dot(d_in, t)) * radiance[c] * falloff *
                  T_in * exp(-sigma_t * s_in - (sigma_t - sigma_ref) * s);
      }
    }
    for (int c = first; c <= last; ++c) L[c] = leaving * sum[c] / (float(n) * sigma_ref);
  }
  return L;
}

#endif
