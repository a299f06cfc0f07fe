// lucent GLSL 1: twin of materials/include/lucent/materials/geometry_factor.h (GeometryFactor): the
// factor per channel by which the object's shape between the entry point (x_i, n_i) and the exit
// point (x_o, n_o) changes a radial profile's multiple scattering (the dipole's flux through the
// exit surface relative to a plane's; 1 on a plane). u_geometry_channels[c] = (sigma_tr, z_r, z_v,
// 1 where the channel scatters), set by gl::set_geometry_factor_uniforms; 1 when
// u_geometry_factor is off. tests/render/glsl_twin_test.cpp holds it against the C++.
#ifndef LUCENT_GEOMETRY_FACTOR_GLSL
#define LUCENT_GEOMETRY_FACTOR_GLSL

uniform bool u_geometry_factor;
uniform vec4 u_geometry_channels[3];

const float kGeometryFactorMax = 64.0;

// (1 + s) e^(s0 - s) / d^3 with s = sigma_tr d, per channel.
vec3 geometry_term(vec3 sigma_tr, vec3 d2, vec3 s0) {
  vec3 d = sqrt(max(d2, vec3(1e-20)));
  vec3 s = sigma_tr * d;
  return (1.0 + s) * exp(s0 - s) / (d2 * d);
}

// g from x_i to x_o, per channel (channels that do not scatter are masked by the caller).
vec3 geometry_one_way(vec3 x_i, vec3 n_i, vec3 x_o, vec3 n_o) {
  vec3 sigma_tr = vec3(u_geometry_channels[0].x, u_geometry_channels[1].x, u_geometry_channels[2].x);
  vec3 z_r = vec3(u_geometry_channels[0].y, u_geometry_channels[1].y, u_geometry_channels[2].y);
  vec3 z_v = vec3(u_geometry_channels[0].z, u_geometry_channels[1].z, u_geometry_channels[2].z);
  vec3 x = x_o - x_i;
  float r2 = dot(x, x);
  vec3 s0 = sigma_tr * sqrt(r2);
  vec3 f_r = geometry_term(sigma_tr, r2 + z_r * z_r, s0);
  vec3 f_v = geometry_term(sigma_tr, r2 + z_v * z_v, s0);
  vec3 planar = z_r * f_r + z_v * f_v;
  float along = dot(x, n_o);
  float x_n = dot(n_i, x);
  vec3 n_star = n_i - (x_n / max(r2, 1e-30)) * x;
  float len = length(n_star);
  n_star = len > 1e-6 ? n_star / len : n_i;
  vec3 tangent =
      clamp(dot(n_star, n_o) + along * (f_r - f_v) / planar, vec3(0.0), vec3(kGeometryFactorMax));
  float cos_io = dot(n_i, n_o);
  float w = clamp(-cos_io, 0.0, 1.0);
  vec3 g = tangent;
  if (w > 0.0) {
    // The sources at x_i -/+ z n_i seen from x_o and from 2 z_b further out along n_o.
    vec3 z_b = 0.5 * (z_v - z_r);
    vec3 a2 = r2 + 2.0 * z_r * x_n + z_r * z_r, a_n = along + z_r * cos_io;
    vec3 b2 = r2 - 2.0 * z_v * x_n + z_v * z_v, b_n = along - z_v * cos_io;
    vec3 flux = geometry_term(sigma_tr, a2, s0) * a_n - geometry_term(sigma_tr, b2, s0) * b_n +
                geometry_term(sigma_tr, a2 + 4.0 * z_b * (a_n + z_b), s0) * (a_n + 2.0 * z_b) -
                geometry_term(sigma_tr, b2 + 4.0 * z_b * (b_n + z_b), s0) * (b_n + 2.0 * z_b);
    g = (1.0 - w) * tangent + w * clamp(flux / planar, vec3(0.0), vec3(kGeometryFactorMax));
  }
  // At x_o = x_i, or where a channel's planar term underflows: 1.
  bvec3 defined = bvec3(r2 > 1e-12 * z_r.x * z_r.x && planar.x > 0.0,
                        r2 > 1e-12 * z_r.y * z_r.y && planar.y > 0.0,
                        r2 > 1e-12 * z_r.z * z_r.z && planar.z > 0.0);
  return mix(vec3(1.0), g, defined);
}

vec3 geometry_factor(vec3 x_i, vec3 n_i, vec3 x_o, vec3 n_o) {
  if (!u_geometry_factor) return vec3(1.0);
  vec3 g = sqrt(geometry_one_way(x_i, n_i, x_o, n_o) * geometry_one_way(x_o, n_o, x_i, n_i));
  bvec3 scatters = bvec3(u_geometry_channels[0].w > 0.5, u_geometry_channels[1].w > 0.5,
                         u_geometry_channels[2].w > 0.5);
  return mix(vec3(1.0), g, scatters);
}

#endif
