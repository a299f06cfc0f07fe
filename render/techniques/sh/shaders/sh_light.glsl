// lucent GLSL 1: the lights of the SH technique (Banterle & Chalmers) and the primary light's shadow map.
// The thickness and every shadow come from one light, the primary (the brightest at the object's
// centre; sh_renderer.h): its depth map stores the distance along its rays (sh_distance), the
// first surface in u_first_depth and the second (one depth-peeling pass) in u_second_depth, 1e30
// where the ray meets nothing.
#ifndef LUCENT_SH_LIGHT_GLSL
#define LUCENT_SH_LIGHT_GLSL

const float kShNoSurface = 1e30;

uniform int u_light_count;
uniform vec4 u_light_position[LUCENT_MAX_LIGHTS];  // w 0: direction toward the light; w 1: point
uniform vec3 u_light_radiance[LUCENT_MAX_LIGHTS];
uniform int u_primary;              // index of the light that casts the shadow map
uniform mat4 u_primary_view_proj;   // its camera
uniform float u_shadow_bias_mm;     // depth bias of the shadow test, mm

// Distance along the primary light's ray: from the light for a point light; for a directional
// light from the plane through the origin normal to it (only differences are used).
float sh_distance(vec3 x) {
  vec4 light = u_light_position[u_primary];
  return light.w > 0.5 ? distance(light.xyz, x) : -dot(light.xyz, x);
}

// Shadow-map coordinates of x, or a negative x when it falls outside the map.
vec2 sh_shadow_uv(vec3 x) {
  vec4 clip = u_primary_view_proj * vec4(x, 1.0);
  if (clip.w <= 0.0) return vec2(-1.0);
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) return vec2(-1.0);
  return uv;
}

// Bias of the shadow test at a surface of normal n lit from w: the base bias (a few shadow-map
// texels) grown with the slope, as a sloped surface spans tan(theta) texels of depth per texel
// (capped at tan = 8).
float sh_shadow_bias(vec3 n, vec3 w) {
  float c = max(abs(dot(n, w)), 0.05);
  return u_shadow_bias_mm * (1.0 + min(sqrt(max(1.0 - c * c, 0.0)) / c, 8.0));
}

// Unit vector toward light l and the irradiance it brings to a surface facing it.
void sh_light_at(int l, vec3 x, out vec3 w, out vec3 E) {
  vec4 light = u_light_position[l];
  if (light.w > 0.5) {
    vec3 to_light = light.xyz - x;
    float d2 = max(dot(to_light, to_light), 1e-12);
    w = to_light * inversesqrt(d2);
    E = u_light_radiance[l] / d2;
  } else {
    w = normalize(light.xyz);
    E = u_light_radiance[l];
  }
}

#endif
