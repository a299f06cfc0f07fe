#version 450 core
// lucent GLSL 1: the hierarchical technique's shading (Mertens et al. eq. 3): L = (1 / pi) F_t(eta,
// n . w_o) B, B interpolated from the vertices, plus (lucent) the single scattering the CPU
// computed at the vertices, plus every light's GGX lobe (unshadowed: the CPU
// shadows the irradiance only) and, with an environment map, its Fresnel reflection.
#include "math.glsl"
#include "fresnel.glsl"
#include "environment.glsl"
#include "specular.glsl"
#include "fur_coat.glsl"
#include "angular.glsl"
#ifdef LUCENT_AREA_LIGHTS
#include "area_light.glsl"
#endif

in vec3 f_position;
in vec3 f_normal;
in vec3 f_B;
in vec3 f_single;  // hierarchical_single.h: Jensen's term at the vertices (F_t, 1 / eta^2 included)
layout(location = 0) out vec4 out_color;

uniform vec3 u_eye;  // mm
uniform float u_eta;
uniform float u_roughness;
uniform bool u_specular;
uniform bool u_has_environment;
uniform sampler2D u_environment;
uniform int u_light_count;
// w 1: point (mm), w 0: direction toward it, w >= 2: area light slot w - 2 (area_light.glsl)
uniform vec4 u_light_position[LUCENT_MAX_LIGHTS];
uniform vec3 u_light_radiance[LUCENT_MAX_LIGHTS];

void main() {
  vec3 x_o = f_position;
  vec3 n_o = normalize(f_normal);
  vec3 w_o = normalize(u_eye - x_o);
  if (dot(n_o, w_o) < 0.0) n_o = -n_o;  // interpolated normals of silhouette triangles
  float cos_o = dot(n_o, w_o);
  float F_r = fresnel_reflectance(cos_o, u_eta);
  vec3 L = (1.0 - F_r) / kPi * angular_factor(cos_o) * max(f_B, vec3(0.0)) +
           max(f_single, vec3(0.0));
  // The mirror direction's light crosses a fur coat too (cos_i = cos_o there; T = 1 without one).
  if (u_has_environment) {
    L += F_r * fur_coat(cos_o) * environment_lookup(u_environment, reflect(-w_o, n_o));
  }
  if (u_specular && u_roughness > 0.0 && cos_o > 0.0) {
    for (int l = 0; l < u_light_count; ++l) {
      vec4 p = u_light_position[l];
#ifdef LUCENT_AREA_LIGHTS
      if (p.w > 1.5) {
        L += u_light_radiance[l] * area_specular(area_slot(p), x_o, n_o, w_o, u_roughness, u_eta);
        continue;
      }
#endif
      vec3 w = p.xyz;
      vec3 E = u_light_radiance[l];
      if (p.w > 0.5) {
        vec3 d = p.xyz - x_o;
        float d2 = max(dot(d, d), 1e-12);
        w = d * inversesqrt(d2);
        E /= d2;
      }
      float cos_i = dot(n_o, w);
      if (!(cos_i > 0.0)) continue;
      vec3 h = normalize(w + w_o);
      L += E * fur_coat(cos_i) * ggx_reflection(cos_i, cos_o, dot(n_o, h), dot(h, w), u_roughness, u_eta);
    }
  }
  out_color = vec4(L, 1.0);
}
