#version 450 core
// lucent GLSL 1: step 3 of seed 003 (§5.2 "Combination", §5.3.5, §5.4.4): the subsurface radiance at
// x_o is the mean, over the layers k whose camera sees x_o, of layer k's gathered sum divided by its
// frame count (alpha), weighted by n_o . w_k (lucent: the seed weighs layers equally), read at the blur level chosen from the frame count; then
//   L(x_o, w_o) = F_t(eta, n_o . w_o) L_ss + F_r(eta, n_o . w_o) L_env(reflect(-w_o, n_o)).
// "Sees" is a shadow-map test against layer k's depth (sampler2DArrayShadow), at x_o shrunk by eps_c
// toward the layer's view axis in the layer plane, x_o - eps_c (n_o - w_k (n_o . w_k)), against the
// seams of seed Figure 5.18. Two changes to the seed's test: the shrink moves x_o sideways under a
// sloped surface by eps_c tan(theta_k) in depth, and the depth texels cover texel tan(theta_k), so
// the bias grows with the slope, eps_b + (eps_c + texel) tan(theta_k) (slope-scaled bias, capped at
// tan = 8), where the seed's constant eps_b fails on sloped surfaces; and layers facing away from
// n_o (n_o . w_k <= 0) are skipped outright, since no camera sees a surface from behind: this is
// what removes the false positives behind silhouettes that the seed's shrink addresses. Alpha out: 1 where some layer sees x_o, 0.5 where none does
// (a hole, seed Figure 5.22); the background pass writes 0.
#include "math.glsl"
#include "fresnel.glsl"
#include "environment.glsl"

in vec3 f_position;
in vec3 f_normal;
layout(location = 0) out vec4 out_color;

layout(std140, binding = 1) uniform LayerCameras {
  mat4 u_layer_view_proj[LUCENT_MAX_DIRECTIONS];
  vec4 u_layer_direction[LUCENT_MAX_DIRECTIONS];
};

uniform sampler2DArrayShadow u_radiance_depth;
uniform sampler2DArray u_radiance;  // trilinear; rgb sums, alpha frame counts
uniform int u_layer_count;
uniform float u_mip_level;
uniform float u_depth_bias_mm;  // eps_b, mm
uniform float u_texel_mm;       // a radiance-map texel, mm
uniform float u_depth_range_mm; // far - near of the layer cameras (depth 0..1), mm
uniform float u_shrink_mm;      // eps_c
uniform vec3 u_eye;          // mm
uniform float u_eta;
uniform bool u_has_environment;
uniform sampler2D u_environment;

void main() {
  vec3 x_o = f_position;
  vec3 n_o = normalize(f_normal);
  vec3 sum = vec3(0.0);
  float seen = 0.0;
  for (int k = 0; k < u_layer_count; ++k) {
    vec3 w_k = u_layer_direction[k].xyz;
    float cos_k = dot(n_o, w_k);
    if (cos_k <= 0.0) continue;
    float tan_k = min(sqrt(max(1.0 - cos_k * cos_k, 0.0)) / cos_k, 8.0);
    float bias = (u_depth_bias_mm + (u_shrink_mm + u_texel_mm) * tan_k) / u_depth_range_mm;
    vec3 x_s = x_o - u_shrink_mm * (n_o - w_k * dot(n_o, w_k));
    vec4 clip = u_layer_view_proj[k] * vec4(x_s, 1.0);
    vec3 p = clip.xyz / clip.w * 0.5 + 0.5;
    if (any(lessThan(p.xy, vec2(0.0))) || any(greaterThan(p.xy, vec2(1.0)))) continue;
    float visible = texture(u_radiance_depth, vec4(p.xy, float(k), p.z - bias));
    if (visible <= 0.0) continue;
    vec4 r = textureLod(u_radiance, vec3(p.xy, float(k)), u_mip_level);
    if (r.a <= 0.0) continue;
    // Weighted by cos_k, the layer's texel density on the surface: a layer that sees x_o edge-on
    // spreads one texel over texel / cos_k of surface (and of the surfaces beside it), so its
    // value is the least accurate; equal weights let one grazing layer of K 8 at W_s 32 take
    // 19% off a flat slab.
    sum += visible * cos_k * r.rgb / r.a;
    seen += visible * cos_k;
  }
  vec3 L_ss = seen > 0.0 ? sum / seen : vec3(0.0);
  vec3 w_o = normalize(u_eye - x_o);
  float F_r = fresnel_reflectance(dot(n_o, w_o), u_eta);
  vec3 L = (1.0 - F_r) * L_ss;
  if (u_has_environment) L += F_r * environment_lookup(u_environment, reflect(-w_o, n_o));
  out_color = vec4(L, seen > 0.0 ? 1.0 : 0.5);
}
