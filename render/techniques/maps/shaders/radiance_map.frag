#version 450 core
// lucent GLSL 1: step 2 of Dal Corso 2014 (§4.1-4.2, §5.2, §5.4.1, §5.5): for the surface point x_o this
// texel of layer k sees, gather the subsurface radiance from the light maps,
//
//   R(x_o) = sum_lights sum_i  w_i E_l(x_i) F_t(eta, n_i . w_l) S_d(x_i, n_i, w_l, x_o, n_o),
//
// over that light's share of the N disc samples d_i (N/L each, seed §5.5.1). The disc lies in the
// plane through x_o perpendicular to w_d (toward the light), rotated per texel and per frame
// (theta_t = 2 pi (random(texel, layer) + t / T), seed §5.4.1); each rotated point is projected into
// the light map, whose texel there holds the surface point x_i nearest to the light on that ray
// (position, shading normal n_i, the normal g_i of its triangle). w_i (mm^2) is the sample's share
// of the disc area with the exponential bias undone, A_c e^(sigma* r_i) / sum_j e^(sigma* r_j)
// (see radiance_maps_sampling.h), so the cosine of the irradiance and the 1 / cos of the projected
// area cancel (seed eq. 4.2) where n_i = g_i; on a faceted mesh their ratio
// (n_i . w_l) / (g_i . w_l) is left (the reference's irradiance is the shading normal's).
//   directional light: E_l = the light's irradiance on a surface facing it;
//   point light: E_l = I (w_i . w_d) / |x_l - d_i|^2, exact for the solid angle the disc element
//   subtends (the seed's I / |x_l - x_i|^2 assumes the disc at the surface).
//   area light (Jacob 1993, an extension of Dal Corso 2014): the light map of frame t is the view from one
//   point s_t of the polygon (Halton points over the frames), so the disc maps to the surface as
//   for a point light at s_t; the irradiance there is the exact pi L F(x_i, n_i) (form_factor.glsl)
//   divided by the fraction a of the polygon above x_i's tangent plane (s_t is visible only from
//   that part), and the point-light mapping's cos_s / |s_t - x_i|^2 is undone. Averaged over the
//   frames: pi L F times the fraction of that part of the polygon x_i sees: exact where the light
//   is unoccluded (soft shadows, and the penumbra's visibility weighted by area, not by the form
//   factor's kernel: a bias inside penumbrae only). w_i = the form factor's vector direction.
//   The undone cos_s is floored at 0.15 (texels s_t sees beyond 81 degrees): their 1 / cos_s weight
//   made fireflies; measured on a marble sphere under a 50 mm rect against the reference (K 8,
//   N 16, 16 frames): no floor 10.0% RMSE, means +4.2%; 0.15: 5.2%, +0.4%; 0.25: 6.4%, -1.8%;
//   0.4: 10.2%, -6.0%.
// The result is added to the previous frame's sum (ping-pong, seed §5.3.3); alpha counts frames.
layout(early_fragment_tests) in;

#include "math.glsl"
#include "fresnel.glsl"
#include "fur_coat.glsl"
#include "angular.glsl"
#include "geometry_factor.glsl"
#include "random.glsl"
#include "bssrdf_ddipole.glsl"
#include "bssrdf_dipole.glsl"
#include "bssrdf_tabulated.glsl"
#ifdef LUCENT_AREA_LIGHTS
#include "area_light.glsl"
#endif

in vec3 g_position;  // x_o, mm
in vec3 g_normal;
flat in int g_layer;

layout(location = 0) out vec4 out_radiance;

layout(std140, binding = 0) uniform LightMatrices {
  mat4 u_light_view_proj[LUCENT_MAX_LIGHTS];
};
// xy: offset in the disc plane (mm); z: weight w_i (mm^2). Light l uses
// [u_light_sample_offset[l], + u_light_sample_count[l]).
layout(std140, binding = 2) uniform DiscSamples {
  vec4 u_disc[LUCENT_MAX_DISC_SAMPLES];
};

uniform sampler2DArray u_light_positions;  // xyz mm, w coverage
uniform sampler2DArray u_light_normals;
uniform sampler2DArray u_light_face_normals;  // the triangle's plane under each texel
uniform sampler2DArray u_previous;         // sum up to the previous frame (other ping-pong buffer)
uniform bool u_has_previous;
uniform bool u_depth_only;                 // depth pre-pass: no gathering

uniform int u_light_count;
uniform vec4 u_light_position[LUCENT_MAX_LIGHTS];  // w = 0: xyz direction toward the light; w = 1: point
uniform vec3 u_light_radiance[LUCENT_MAX_LIGHTS];  // irradiance (directional) or intensity (point)
uniform int u_light_sample_offset[LUCENT_MAX_LIGHTS];
uniform int u_light_sample_count[LUCENT_MAX_LIGHTS];
// A light-map texel's width at the surface, mm: x + y * (distance from the light), x for
// directional lights (orthographic), y for point lights (perspective).
uniform vec2 u_light_texel_mm[LUCENT_MAX_LIGHTS];

uniform float u_rotation_offset;  // t / T
uniform float u_eta;
uniform DdipoleChannel u_ddipole[3];
uniform DipoleChannel u_dipole[3];
uniform TabulatedChannel u_tabulated[3];
uniform sampler2D u_tabulated_rows;

// Orthonormal basis around a unit vector (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited").
void basis(vec3 n, out vec3 b1, out vec3 b2) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float b = n.x * n.y * a;
  b1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  b2 = vec3(b, s + n.y * n.y * a, -n.y);
}

// S_d per channel; the radial models take the oblique beam's skew (angular.glsl; 1 when off).
vec3 bssrdf(vec3 x_i, vec3 n_i, vec3 w_i, vec3 x_o, vec3 n_o) {
#if defined(LUCENT_MODEL_DDIPOLE)
  return ddipole_S_d_rgb(u_ddipole, x_i, n_i, w_i, x_o, n_o);
#else
  float r = distance(x_o, x_i);
  vec3 skew = oblique_skew(x_o - x_i, oblique_displacement(w_i, n_i, u_eta));
#if defined(LUCENT_MODEL_DIPOLE)
  return dipole_S_d_rgb(u_dipole, r) * skew;
#else
  return vec3(tabulated_S_d(u_tabulated_rows, u_tabulated[0], r),
              tabulated_S_d(u_tabulated_rows, u_tabulated[1], r),
              tabulated_S_d(u_tabulated_rows, u_tabulated[2], r)) * skew;
#endif
#endif
}

void main() {
  if (u_depth_only) {
    out_radiance = vec4(0.0);
    return;
  }
  vec3 x_o = g_position;
  vec3 n_o = normalize(g_normal);
  ivec2 texel = ivec2(gl_FragCoord.xy);
  float angle = 2.0 * kPi * (texel_random(texel, g_layer) + u_rotation_offset);
  mat2 rotation = mat2(cos(angle), sin(angle), -sin(angle), cos(angle));
  vec2 light_map_size = vec2(textureSize(u_light_positions, 0).xy);

  vec3 sum = vec3(0.0);
  for (int l = 0; l < u_light_count; ++l) {
    vec4 light = u_light_position[l];
    bool is_point = light.w > 0.5;  // point or area (from this frame's point s_t)
#ifdef LUCENT_AREA_LIGHTS
    bool is_area = light.w > 1.5;
#endif
    vec3 w_d = is_point ? normalize(light.xyz - x_o) : normalize(light.xyz);
    vec3 t1, t2;
    basis(w_d, t1, t2);
    mat4 view_proj = u_light_view_proj[l];
    int first = u_light_sample_offset[l];
    int end = first + u_light_sample_count[l];
    for (int i = first; i < end; ++i) {
      vec4 sample_ = u_disc[i];
      vec2 d = rotation * sample_.xy;
      vec3 x_d = x_o + d.x * t1 + d.y * t2;
      vec4 clip = view_proj * vec4(x_d, 1.0);
      if (clip.w <= 0.0) continue;
      vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
      if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) continue;
      ivec3 at = ivec3(ivec2(uv * light_map_size), l);
      vec4 p = texelFetch(u_light_positions, at, 0);
      if (p.w < 0.5) continue;  // no surface on this ray
      vec3 n_i = texelFetch(u_light_normals, at, 0).xyz;
      // The texel holds the surface point at its centre; the disc point's own ray (along w_d, or
      // from the point light through x_d) meets the surface elsewhere in the texel. Intersecting
      // that ray with the plane of the triangle under the texel's centre puts x_i where the
      // sample's weight says it is, at any light-map resolution (texels larger than a mean free
      // path otherwise move every near sample by up to half a texel, which biases the sum by the
      // profile's curvature). The triangle's plane, not the shading normal's: on a faceted mesh
      // the interpolated normal tilts that plane off the surface by degrees, so near samples
      // landed a texel x tan(tilt) above or below it; on dragon:4 that took 6-26% off a material
      // whose mean free path is 0.01-0.05 mm (the dense medium of faceted_mesh_test).
      // Kept to a few texels along the ray, so grazing texels fall back to their centre.
      vec3 n_plane = texelFetch(u_light_face_normals, at, 0).xyz;
      vec3 origin = is_point ? light.xyz : x_d;
      vec3 ray = is_point ? normalize(x_d - light.xyz) : -w_d;
      float along = dot(n_plane, ray);
      vec3 x_i = p.xyz;
      if (along < -0.05) {
        float s = dot(p.xyz - origin, n_plane) / along;
        vec3 hit = origin + s * ray;
        float texel = u_light_texel_mm[l].x + u_light_texel_mm[l].y * distance(origin, p.xyz);
        if (distance(hit, p.xyz) <= 4.0 * texel) x_i = hit;
      }
      vec3 w_i;
      vec3 E;
#ifdef LUCENT_AREA_LIGHTS
      if (is_area) {
        int slot = area_slot(light);
        FormFactor ff = area_form_factor(slot, x_i, n_i);
        vec3 to_s = light.xyz - x_i;
        float d_s = length(to_s);
        // The disc maps onto the triangle's plane (the light map's projection from s_t), so
        // the mapping's cos_s is the triangle's; the irradiance pi L F is the shading normal's.
        float cos_s = d_s > 0.0 ? dot(n_plane, to_s) / d_s : 0.0;
        float above = ff.clipped_area / area_light_area(slot);
        if (!(ff.F > 0.0) || !(cos_s > 0.0) || !(above > 1e-6)) continue;
        w_i = normalize(ff.vector_);
        vec3 from_disc = light.xyz - x_d;
        E = u_light_radiance[l] * (kPi * ff.F / above) * (d_s * d_s / max(cos_s, 0.15)) *
            max(dot(to_s / d_s, w_d), 0.0) / dot(from_disc, from_disc);
      } else
#endif
      if (is_point) {
        vec3 to_light = light.xyz - x_i;
        w_i = normalize(to_light);
        vec3 from_disc = light.xyz - x_d;
        E = u_light_radiance[l] * max(dot(w_i, w_d), 0.0) / dot(from_disc, from_disc);
      } else {
        w_i = w_d;
        E = u_light_radiance[l];
      }
      float cos_i = dot(n_i, w_i);
      if (cos_i <= 0.0) continue;  // interpolated normal turned away at a silhouette
      // The disc's area maps onto the triangle's own area (the light map's projection), so E
      // above is the irradiance across the triangle's plane, E cos_g; the light entering the
      // surface is E cos_i with the shading normal, as the reference (and pbrt, Mitsuba) have
      // it. On a faceted mesh the two differ point by point: on dragon:4, without this factor,
      // the maps were 2.3% darker than the reference in every material (and exact on the same
      // mesh flat-shaded). cos_g is floored at 0.15, as the area lights' cos_s above, for the
      // texels a light sees at grazing incidence. (An area light's E is already the shading
      // normal's: its mapping is undone with cos_g above.)
#ifdef LUCENT_AREA_LIGHTS
      if (!is_area)
#endif
      E *= cos_i / max(dot(n_plane, w_i), 0.15);
      // The shape's factor places the beam's sources along its refracted direction where the
      // skew is on (as the reference does); the exit's view is not known here: the entry's side.
      vec3 d_i = any(greaterThan(u_mean_free_path, vec3(0.0)))
                     ? oblique_displacement(w_i, n_i, u_eta)
                     : vec3(0.0);
      sum += sample_.z * fresnel_transmittance(cos_i, u_eta) * fur_coat(cos_i) * E *
             bssrdf(x_i, n_i, w_i, x_o, n_o) * angular_factor(cos_i) *
             geometry_factor(x_i, n_i, d_i, x_o, n_o);
    }
  }
  vec4 previous = u_has_previous ? texelFetch(u_previous, ivec3(texel, g_layer), 0) : vec4(0.0);
  out_radiance = previous + vec4(sum, 1.0);
}
