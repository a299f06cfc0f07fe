#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 4, the final pass. At a visible point x_o with normal n_o:
//   r = refract(-w_o, n_o, 1 / eta)            the refracted view ray into the object;
//   p = its exit from the bounding box          (the seed's fix of the "shift" problem);
//   B_c = q^T M_c q, q = p's cube direction     (eq. 10, M_c built from the GPU projection);
//   d = distance to the primary light - the blurred first depth there, the thickness along the
//       light's ray; 0 scattering where x_o lies beyond the second depth (the seed's Figure 9),
//       the test percentage-closer filtered over 3 x 3 texels (an extension: no terminator speckle);
//   L_ss,c = (1 / pi) F_t(eta, n_o . w_o) a_c(d) B_c   (eq. 10 with eq. 12's attenuation a_c and
//       the d_eff guard), or (u_slab) eq. 12 integrated over the plane at d; each channel times
//       u_attenuation_scale (ShAttenuation: R_tot / a_c(0), so that d = 0 shows (1 / pi) F_t
//       R_tot B, or 1 for the seed's).
// Front lighting (the seed leaves it out): no separate diffuse term. A point the primary light
// sees directly has d = 0 and takes a_c(0) B_c, the same scattering term at its thinnest; the
// surface reflection of every light is the specular lobe (specular.glsl, the primary light
// shadowed, the others not), and an environment map adds F_r L_env(reflect(-w_o, n_o)).
// u_output 1 writes (d, the fraction beyond the second depth, lit by the primary ? 1 : 0), 2 writes x_o
// (mm): the tests read them.
#include "math.glsl"
#include "fresnel.glsl"
#include "environment.glsl"
#include "specular.glsl"
#include "sh_math.glsl"
#include "sh_light.glsl"

in vec3 f_position;
in vec3 f_normal;
layout(location = 0) out vec4 out_color;

layout(std430, binding = 1) readonly buffer Coefficients { float coefficients[27]; };
uniform sampler2D u_first_depth;    // unblurred: shadow tests
uniform sampler2D u_blurred_depth;  // blurred: thickness
uniform sampler2D u_second_depth;
uniform vec3 u_box_min, u_box_max;  // mm, the cube map's box
uniform vec3 u_eye;                 // mm
uniform float u_eta;
uniform vec3 u_sigma_tr;            // mm^-1, per channel
uniform vec3 u_sigma_t_reduced;     // mm^-1, per channel
uniform vec3 u_attenuation_scale;   // R_tot / a(0) per channel (normalised, slab), or 1 (seed)
uniform bool u_slab;                // eq. 12 integrated over the plane (ShAttenuation::kSlab)
uniform float u_roughness;
uniform bool u_specular;
uniform bool u_has_environment;
uniform sampler2D u_environment;
uniform int u_output;

float fetch(sampler2D map, vec2 uv) {
  ivec2 size = textureSize(map, 0);
  return texelFetch(map, min(ivec2(uv * vec2(size)), size - 1), 0).r;
}

// Bilinear over the texels that hold a surface (weights renormalised): the thickness follows the
// surface between texel centres instead of stepping, which at grazing light stretches each texel
// over many pixels along the terminator.
float fetch_bilinear_surface(sampler2D map, vec2 uv) {
  ivec2 size = textureSize(map, 0);
  vec2 p = uv * vec2(size) - 0.5;
  ivec2 p0 = ivec2(floor(p));
  vec2 f = p - vec2(p0);
  float sum = 0.0, weight = 0.0;
  for (int j = 0; j <= 1; ++j)
    for (int i = 0; i <= 1; ++i) {
      float v = texelFetch(map, clamp(p0 + ivec2(i, j), ivec2(0), size - 1), 0).r;
      float w = (i == 1 ? f.x : 1.0 - f.x) * (j == 1 ? f.y : 1.0 - f.y);
      if (v < kShNoSurface * 0.5) {
        sum += w * v;
        weight += w;
      }
    }
  return weight > 0.0 ? sum / weight : kShNoSurface;
}

void main() {
  vec3 x_o = f_position;
  vec3 n_o = normalize(f_normal);
  vec3 w_o = normalize(u_eye - x_o);
  if (dot(n_o, w_o) < 0.0) n_o = -n_o;  // interpolated normals of silhouette triangles

  // Thickness along the primary light's ray.
  float d = 0.0;
  float beyond_fraction = 0.0;
  bool lit = false;
  vec2 uv = sh_shadow_uv(x_o);
  vec3 w_p, E_p;
  sh_light_at(u_primary, x_o, w_p, E_p);
  if (uv.x >= 0.0) {
    float t = sh_distance(x_o);
    float blurred = fetch_bilinear_surface(u_blurred_depth, uv);
    float first = fetch(u_first_depth, uv);
    float bias = sh_shadow_bias(n_o, w_p);
    if (blurred < kShNoSurface * 0.5) d = max(t - blurred, 0.0);
    // The beyond-the-second-depth test, percentage-closer filtered over 3 x 3 texels: at grazing
    // light the second depth changes by many biases from one texel to the next, and a single
    // comparison flickers into speckle along the terminator.
    ivec2 size = textureSize(u_second_depth, 0);
    ivec2 centre = min(ivec2(uv * vec2(size)), size - 1);
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i) {
        float s = texelFetch(u_second_depth, clamp(centre + ivec2(i, j), ivec2(0), size - 1), 0).r;
        beyond_fraction += (s < kShNoSurface * 0.5 && t > s + bias) ? 1.0 / 9.0 : 0.0;
      }
    // A surface facing away from the light is never lit by it, whatever the biased test says.
    lit = dot(n_o, w_p) > 0.0 && (first >= kShNoSurface * 0.5 || t <= first + bias);
  }
  if (u_output == 1) {
    out_color = vec4(d, beyond_fraction, lit ? 1.0 : 0.0, 1.0);
    return;
  }
  if (u_output == 2) {
    out_color = vec4(x_o, 1.0);
    return;
  }

  vec3 L = vec3(0.0);
  float cos_o = dot(n_o, w_o);
  float F_r = fresnel_reflectance(cos_o, u_eta);
  if (beyond_fraction < 1.0) {
    vec3 r = refract(-w_o, n_o, 1.0 / u_eta);
    if (dot(r, r) > 0.0) {
      vec3 q = sh_box_lookup_direction(u_box_min, u_box_max,
                                       sh_ray_box_exit(u_box_min, u_box_max, x_o, r));
      float e[27];
      for (int k = 0; k < 27; ++k) e[k] = coefficients[k];
      for (int c = 0; c < 3; ++c) {
        float B = max(sh_irradiance(sh_irradiance_matrix(e, 9 * c), q), 0.0);
        L[c] = (1.0 - beyond_fraction) * (1.0 - F_r) / kPi * u_attenuation_scale[c] *
               (u_slab ? sh_attenuation_slab(d, u_sigma_tr[c], u_sigma_t_reduced[c])
                       : sh_attenuation(d, u_sigma_tr[c], u_sigma_t_reduced[c])) * B;
      }
    }
  }
  if (u_has_environment) L += F_r * environment_lookup(u_environment, reflect(-w_o, n_o));
  if (u_specular && u_roughness > 0.0 && cos_o > 0.0) {
    for (int l = 0; l < u_light_count; ++l) {
      vec3 w, E;
      sh_light_at(l, x_o, w, E);
      float cos_i = dot(n_o, w);
      if (!(cos_i > 0.0) || (l == u_primary && !lit)) continue;
      vec3 h = normalize(w + w_o);
      L += E * ggx_reflection(cos_i, cos_o, dot(n_o, h), dot(h, w), u_roughness, u_eta);
    }
  }
  out_color = vec4(L, 1.0);
}
