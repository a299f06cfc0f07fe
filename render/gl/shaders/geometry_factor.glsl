// lucent GLSL 1: twin of materials/include/lucent/materials/geometry_factor.h (GeometryFactor): the
// factor per channel by which the object's shape between the entry point (x_i, n_i) and the exit
// point (x_o, n_o) changes a radial profile's multiple scattering: the flux of each beam's
// diffusion sources (three along its refracted direction, each with its Kelvin image) through the
// osculating sphere over a plane's at the same chord (1 on a plane); the entry's side only.
// u_geometry_channels[c] = (sigma_tr, z_r, z_v, 1 where the channel scatters), set by
// gl::set_geometry_factor_uniforms; 1 when u_geometry_factor is off.
// tests/render/geometry_factor_test.cpp holds it against the C++.
#ifndef LUCENT_GEOMETRY_FACTOR_GLSL
#define LUCENT_GEOMETRY_FACTOR_GLSL

uniform bool u_geometry_factor;
uniform vec4 u_geometry_channels[3];

const float kGeometryFactorMax = 64.0;
const float kBeamDepths[3] = float[3](0.4157745568, 2.2942803603, 6.2899450829);
const float kBeamDepthWeights[3] = float[3](0.7110930099, 0.2785177336, 0.0103892565);

// (1 + s) e^(s0 - s) / d^3 with s = sigma_tr d, per channel.
vec3 geometry_term(vec3 sigma_tr, vec3 d2, vec3 s0) {
  vec3 d = sqrt(max(d2, vec3(1e-20)));
  vec3 s = sigma_tr * d;
  return (1.0 + s) * exp(s0 - s) / (d2 * d);
}

// One way, per channel: from the entry (origin, normal n, beam d: the refracted direction's
// tangential part) to the exit x away, on the sphere of curvature inv_a (GeometryFactor::one_way).
vec3 geometry_one_way(vec3 x, vec3 n, vec3 d, float inv_a_raw, vec3 sigma_tr, vec3 z_r, vec3 z_b) {
  vec3 t = x - dot(x, n) * n;
  if (!(dot(t, t) > 1e-20 * dot(x, x))) t = d - dot(d, n) * n;
  if (!(dot(t, t) > 1e-30))
    t = abs(n.x) < 0.9 ? cross(n, vec3(1.0, 0.0, 0.0)) : cross(n, vec3(0.0, 1.0, 0.0));
  t = normalize(t);
  vec3 b = cross(n, t);
  float w_t = dot(d, t), w_b = dot(d, b);
  float cos_t = sqrt(max(1.0 - w_t * w_t - w_b * w_b, 0.0));
  float r = length(x);
  vec3 inv_a = clamp(vec3(inv_a_raw), -0.5 / z_b, 1.0 / z_r);
  vec3 half_sin = clamp(0.5 * r * inv_a, vec3(-1.0), vec3(1.0));
  vec3 half_cos = sqrt(1.0 - half_sin * half_sin);
  vec3 sin_g = 2.0 * half_sin * half_cos, cos_g = 1.0 - 2.0 * half_sin * half_sin;
  vec3 x_t = r * half_cos, x_n = -r * half_sin;
  vec3 reach =
      mix(vec3(3.0e38), 0.9 * cos_t / max(inv_a, vec3(1e-30)), greaterThan(inv_a, vec3(0.0)));
  vec3 s0 = sigma_tr * r;
  vec3 lift = 1.0 + z_b * inv_a;
  vec3 sphere = vec3(0.0), plane = vec3(0.0);
  for (int k = 0; k < 3; ++k) {
    vec3 s = min(kBeamDepths[k] * z_r, reach);
    vec3 u_t = s * w_t, u_b = s * w_b, u_n = -s * cos_t;
    vec3 lateral = (r - u_t) * (r - u_t) + u_b * u_b;
    vec3 above = 2.0 * z_b - u_n;
    plane += kBeamDepthWeights[k] * (-u_n * geometry_term(sigma_tr, lateral + u_n * u_n, s0) +
                                     above * geometry_term(sigma_tr, lateral + above * above, s0));
    vec3 den = 1.0 + 2.0 * u_n * inv_a + s * s * inv_a * inv_a;
    vec3 rho = lift * lift / den;
    vec3 i_t = rho * u_t, i_b = rho * u_b;
    vec3 i_n = rho * u_n + (2.0 * z_b + z_b * z_b * inv_a - 2.0 * u_n - s * s * inv_a) / den;
    vec3 e_t = x_t - u_t, e_n = x_n - u_n, f_t = x_t - i_t, f_n = x_n - i_n;
    sphere += kBeamDepthWeights[k] *
              (geometry_term(sigma_tr, e_t * e_t + u_b * u_b + e_n * e_n, s0) *
                   (e_t * sin_g + e_n * cos_g) -
               lift / sqrt(den) * geometry_term(sigma_tr, f_t * f_t + i_b * i_b + f_n * f_n, s0) *
                   (f_t * sin_g + f_n * cos_g));
  }
  vec3 g = clamp(sphere / plane, vec3(0.0), vec3(kGeometryFactorMax));
  return mix(vec3(1.0), g, bvec3(inv_a.x != 0.0 && plane.x > 0.0, inv_a.y != 0.0 && plane.y > 0.0,
                                 inv_a.z != 0.0 && plane.z > 0.0));
}

// G for a beam entering at x_i (normal n_i) with refracted tangential part d_i and light leaving at
// x_o (n_o): the entry's one-way factor (GeometryFactor::from_entry), the maps' form: the gather
// does not know the exit's view, and the reciprocal mean with a normal exit's cost the render a sixth
// more on llvmpipe and gave the far field a normal beam's gain.
vec3 geometry_factor(vec3 x_i, vec3 n_i, vec3 d_i, vec3 x_o, vec3 n_o) {
  if (!u_geometry_factor) return vec3(1.0);
  vec3 sigma_tr =
      vec3(u_geometry_channels[0].x, u_geometry_channels[1].x, u_geometry_channels[2].x);
  vec3 z_r = vec3(u_geometry_channels[0].y, u_geometry_channels[1].y, u_geometry_channels[2].y);
  vec3 z_v = vec3(u_geometry_channels[0].z, u_geometry_channels[1].z, u_geometry_channels[2].z);
  vec3 z_b = 0.5 * (z_v - z_r);
  vec3 x = x_o - x_i;
  float r2 = dot(x, x);
  float inv_a = dot(x, n_o - n_i) / max(r2, 1e-30);
  vec3 g = geometry_one_way(x, n_i, d_i, inv_a, sigma_tr, z_r, z_b);
  // Coincident points, or a channel that does not scatter: 1.
  bvec3 defined = bvec3(r2 > 1e-12 * z_r.x * z_r.x && u_geometry_channels[0].w > 0.5,
                        r2 > 1e-12 * z_r.y * z_r.y && u_geometry_channels[1].w > 0.5,
                        r2 > 1e-12 * z_r.z * z_r.z && u_geometry_channels[2].w > 0.5);
  return mix(vec3(1.0), g, defined);
}

#endif
