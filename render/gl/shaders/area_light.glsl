// lucent GLSL 1: polygonal area lights (Jacob 1993) for the GPU techniques: the polygons as uniforms,
// their exact form factor (form_factor.glsl) and the specular lobe of one. A light whose
// u_light_position w is >= 2 is area light slot int(w) - 2; its xyz is the point of the polygon the
// current frame's light map was rendered from.
#ifndef LUCENT_AREA_LIGHT_GLSL
#define LUCENT_AREA_LIGHT_GLSL

#include "form_factor.glsl"
#include "fur_coat.glsl"
#include "specular.glsl"

// Per slot, LUCENT_MAX_POLYGON_VERTICES entries: xyz a vertex (mm); the w components hold the
// vertex count (entry 0), the area in mm^2 (1) and the unit emitting normal (2..4).
uniform vec4 u_area_vertices[LUCENT_MAX_AREA_LIGHTS * LUCENT_MAX_POLYGON_VERTICES];

int area_slot(vec4 light_position) { return int(light_position.w + 0.5) - 2; }

FormFactor area_form_factor(int slot, vec3 x, vec3 n) {
  vec3 p[LUCENT_MAX_POLYGON_VERTICES];
  int base = slot * LUCENT_MAX_POLYGON_VERTICES;
  int count = int(u_area_vertices[base].w + 0.5);
  for (int i = 0; i < LUCENT_MAX_POLYGON_VERTICES; ++i) p[i] = u_area_vertices[base + i].xyz;
  return polygon_form_factor(x, n, p, count);
}

float area_light_area(int slot) { return u_area_vertices[slot * LUCENT_MAX_POLYGON_VERTICES + 1].w; }

vec3 area_light_normal(int slot) {
  int base = slot * LUCENT_MAX_POLYGON_VERTICES;
  return vec3(u_area_vertices[base + 2].w, u_area_vertices[base + 3].w, u_area_vertices[base + 4].w);
}

// The GGX lobe of an area light per unit radiance, by the representative point (Karis 2013, "Real
// Shading in Unreal Engine 4"): the point of the polygon nearest the mirror ray, lit with the exact
// irradiance pi F over its cosine, the lobe's energy normalised by (alpha / alpha')^2 with
// alpha' = alpha + r / (2 d), r the radius of a disc of the polygon's area. An approximation (the
// CPU reference integrates the lobe over the polygon); no shadow test. Under a fur coat the
// lobe takes the coat's T at the representative point's cosine (fur_coat.glsl).
float area_specular(int slot, vec3 x, vec3 n, vec3 w_o, float alpha, float eta) {
  float cos_o = dot(n, w_o);
  if (!(cos_o > 0.0) || !(alpha > 0.0)) return 0.0;
  FormFactor ff = area_form_factor(slot, x, n);
  if (!(ff.F > 0.0)) return 0.0;
  int base = slot * LUCENT_MAX_POLYGON_VERTICES;
  int count = int(u_area_vertices[base].w + 0.5);
  vec3 N = area_light_normal(slot);
  vec3 r = reflect(-w_o, n);
  vec3 p0 = u_area_vertices[base].xyz;
  float denom = dot(r, N);
  vec3 q = ff.vector_ * 1e3 + x;  // fallback: along the irradiance direction
  if (denom < -1e-6) {
    float t = dot(p0 - x, N) / denom;
    if (t > 0.0) q = x + t * r;
  }
  // Onto the plane, then into the (convex) polygon: outside an edge, onto that edge's segment.
  q -= dot(q - p0, N) * N;
  for (int i = 0; i < count; ++i) {
    vec3 a = u_area_vertices[base + i].xyz;
    vec3 b = u_area_vertices[base + (i + 1) % count].xyz;
    if (dot(cross(b - a, q - a), N) < 0.0) {
      vec3 e = b - a;
      q = a + clamp(dot(q - a, e) / dot(e, e), 0.0, 1.0) * e;
    }
  }
  vec3 d = q - x;
  float dist = length(d);
  if (!(dist > 0.0)) return 0.0;
  vec3 w = d / dist;
  float cos_i = dot(n, w);
  if (!(cos_i > 0.0)) return 0.0;
  float radius = sqrt(area_light_area(slot) / kPi);
  float widened = min(alpha + 0.5 * radius / dist, 1.0);
  float normalisation = (alpha / widened) * (alpha / widened);
  vec3 h = normalize(w + w_o);
  return kPi * ff.F / cos_i * normalisation * fur_coat(cos_i) *
         ggx_reflection(cos_i, cos_o, dot(n, h), dot(h, w), alpha, eta);
}

#endif
