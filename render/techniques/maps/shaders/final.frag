#version 450 core
// lucent GLSL 1: step 3 of Dal Corso 2014 (§5.2 "Combination", §5.3.5, §5.4.4): the subsurface radiance at
// x_o is the mean, over the layers k whose camera sees x_o, of layer k's gathered sum divided by its
// frame count (alpha), weighted by n_o . w_k (lucent: the seed weighs layers equally), read at the blur level chosen from the frame count; then
//   L(x_o, w_o) = F_t(eta, n_o . w_o) L_ss + F_r(eta, n_o . w_o) L_env(reflect(-w_o, n_o)),
// plus (lucent) the single scattering of the point and directional lights (single_scattering.glsl).
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
#include "specular.glsl"
#include "fur_coat.glsl"
#include "single_scattering.glsl"
#include "angular.glsl"
#ifdef LUCENT_AREA_LIGHTS
#include "area_light.glsl"
#endif

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
uniform bool u_cos_weighted_layers;  // false: the seed's equal weights
uniform vec3 u_eye;          // mm
uniform float u_eta;
uniform bool u_has_environment;
uniform sampler2D u_environment;

// The lights, for the specular lobe (as in radiance_map.frag), and the light maps' surface
// positions for its shadow test.
layout(std140, binding = 0) uniform LightMatrices {
  mat4 u_light_view_proj[LUCENT_MAX_LIGHTS];
};
uniform int u_light_count;
uniform vec4 u_light_position[LUCENT_MAX_LIGHTS];
uniform vec3 u_light_radiance[LUCENT_MAX_LIGHTS];
uniform vec2 u_light_texel_mm[LUCENT_MAX_LIGHTS];
uniform sampler2DArray u_light_positions;
uniform float u_roughness;  // GGX alpha; 0: no lobe from point or directional lights
uniform bool u_specular;
// The single-scattering term (Scene::single_scattering): the medium and the quadrature's steps; the
// light maps' normals give the light's entry point.
uniform bool u_single_scattering;
uniform vec3 u_single_sigma_s;  // mm^-1
uniform vec3 u_single_sigma_t;  // mm^-1
uniform vec3 u_single_g;
uniform int u_single_steps;
uniform sampler2DArray u_light_normals;       // shading normals of the light maps' surfaces
uniform sampler2DArray u_light_face_normals;  // their triangles' planes

// Whether light l reaches x_o: the light map's nearest surface on x_o's ray toward the light is
// x_o itself (within a slope-scaled bias of a few light-map texels) and not something in front.
bool lit_by(int l, vec3 x_o, vec3 n_o, vec3 w) {
  vec4 clip = u_light_view_proj[l] * vec4(x_o, 1.0);
  if (clip.w <= 0.0) return false;
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) return false;
  vec2 size = vec2(textureSize(u_light_positions, 0).xy);
  vec4 p = texelFetch(u_light_positions, ivec3(ivec2(uv * size), l), 0);
  if (p.w < 0.5) return true;
  vec4 light = u_light_position[l];
  float texel = u_light_texel_mm[l].x + u_light_texel_mm[l].y * distance(light.xyz, x_o);
  float cos_i = max(dot(n_o, w), 0.05);
  float bias = 2.0 * texel * (1.0 + min(sqrt(1.0 - cos_i * cos_i) / cos_i, 8.0));
  return dot(p.xyz - x_o, w) <= bias;
}

// The light's entry point from x (inside) toward light l: the light map's surface in x's texel,
// its distance along w to the plane of that surface's triangle (the texel's position alone would be
// off by up to a texel times the slope), and its shading normal. No surface there: x is outside.
bool single_scattering_entry(int l, vec3 x, vec3 w, out float distance_mm, out vec3 normal) {
  distance_mm = 0.0;
  normal = w;
  vec4 clip = u_light_view_proj[l] * vec4(x, 1.0);
  if (clip.w <= 0.0) return false;
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) return false;
  vec2 size = vec2(textureSize(u_light_positions, 0).xy);
  ivec3 texel = ivec3(ivec2(uv * size), l);
  vec4 p = texelFetch(u_light_positions, texel, 0);
  if (p.w < 0.5) return false;
  vec3 plane = texelFetch(u_light_face_normals, texel, 0).xyz;
  normal = texelFetch(u_light_normals, texel, 0).xyz;
  float along = dot(w, plane);
  distance_mm = along > 0.05 ? dot(p.xyz - x, plane) / along : dot(p.xyz - x, w);
  return true;
}

// Every point and directional light's single scattering (area lights have none here).
vec3 single_scattering_lights(vec3 x_o, vec3 n_o, vec3 w_o) {
  SingleMedium m = SingleMedium(u_single_sigma_s, u_single_sigma_t, u_single_g, u_eta);
  vec3 sum = vec3(0.0);
  for (int l = 0; l < u_light_count; ++l) {
    if (u_light_position[l].w > 1.5) continue;
    sum += single_scattering_radiance(m, x_o, n_o, w_o, l, u_light_position[l],
                                      u_light_radiance[l], u_single_steps);
  }
  return sum;
}

vec3 specular_lights(vec3 x_o, vec3 n_o, vec3 w_o) {
  vec3 sum = vec3(0.0);
  if (!u_specular || !(u_roughness > 0.0)) return sum;
  float cos_o = dot(n_o, w_o);
  if (!(cos_o > 0.0)) return sum;
  for (int l = 0; l < u_light_count; ++l) {
    vec4 light = u_light_position[l];
#ifdef LUCENT_AREA_LIGHTS
    if (light.w > 1.5) {
      sum += u_light_radiance[l] *
             area_specular(area_slot(light), x_o, n_o, w_o, u_roughness, u_eta);
      continue;
    }
#endif
    bool is_point = light.w > 0.5;
    vec3 to_light = is_point ? light.xyz - x_o : light.xyz;
    vec3 w = normalize(to_light);
    float cos_i = dot(n_o, w);
    if (!(cos_i > 0.0) || !lit_by(l, x_o, n_o, w)) continue;
    vec3 E = u_light_radiance[l] / (is_point ? dot(to_light, to_light) : 1.0);
    vec3 h = normalize(w + w_o);
    sum += E * fur_coat(cos_i) * ggx_reflection(cos_i, cos_o, dot(n_o, h), dot(h, w), u_roughness, u_eta);
  }
  return sum;
}

// The gathered radiance of layer k at the exit point displaced, per channel, along the view's
// oblique beam (by reciprocity with the entry's, angular.glsl): each channel read at its own point
// (x_s + shift u_mean_free_path[c]); where that falls off the layer's map, x_o's own value.
vec3 displaced_exit(int k, vec3 x_s, vec3 shift, vec3 value) {
  for (int c = 0; c < 3; ++c) {
    if (!(u_mean_free_path[c] > 0.0)) continue;
    vec4 clip = u_layer_view_proj[k] * vec4(x_s + u_mean_free_path[c] * shift, 1.0);
    vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) continue;
    vec4 r = textureLod(u_radiance, vec3(uv, float(k)), u_mip_level);
    if (r.a > 0.0) value[c] = r[c] / r.a;
  }
  return value;
}

void main() {
  vec3 x_o = f_position;
  vec3 n_o = normalize(f_normal);
  vec3 w_o = normalize(u_eye - x_o);
  vec3 exit_shift = oblique_displacement(w_o, n_o, u_eta);
  bool displaced = any(greaterThan(u_mean_free_path, vec3(0.0)));
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
    // 19% off a flat slab. (u_cos_weighted_layers false: the seed's equal weights.)
    vec3 value = r.rgb / r.a;
    if (displaced) value = displaced_exit(k, x_s, exit_shift, value);
    float weight = u_cos_weighted_layers ? cos_k : 1.0;
    sum += visible * weight * value;
    seen += visible * weight;
  }
  vec3 L_ss = seen > 0.0 ? sum / seen : vec3(0.0);
  float F_r = fresnel_reflectance(dot(n_o, w_o), u_eta);
  vec3 L = (1.0 - F_r) * angular_factor(dot(n_o, w_o)) * L_ss;
  // The mirror direction's light crosses a fur coat too (cos_i = cos_o there; T = 1 without one).
  if (u_has_environment && u_specular) {  // --specular off: the subsurface term alone
    L += F_r * fur_coat(dot(n_o, w_o)) * environment_lookup(u_environment, reflect(-w_o, n_o));
  }
  if (u_single_scattering) L += single_scattering_lights(x_o, n_o, w_o);
  L += specular_lights(x_o, n_o, w_o);
  out_color = vec4(L, seen > 0.0 ? 1.0 : 0.5);
}
