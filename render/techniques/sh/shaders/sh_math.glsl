// lucent GLSL 1: twin of render/techniques/sh/sh_translucency.h (Banterle & Chalmers, the SH fast
// translucency technique): the Ramamoorthi-Hanrahan real basis of bands 0-2 (no Condon-Shortley
// phase), the cube-map texel geometry and differential solid angle, the symmetric 4x4 irradiance
// matrix (row 4 as R&H, not the seed's misprint), eq. 12's attenuation with the d_eff = sqrt(d^2 +
// z_r^2) guard, and the ray-box look-up of the "shift" and "blindness" fixes. The C++ header holds
// the derivations and references; tests/render/sh_renderer_test.cpp holds this file against it.
#ifndef LUCENT_SH_MATH_GLSL
#define LUCENT_SH_MATH_GLSL

// Exact constants (sh_translucency.h basis_constants(), irradiance_constants()).
const float kShY00 = 0.28209479177387814;   // 1 / (2 sqrt(pi))
const float kShY1 = 0.4886025119029199;     // sqrt(3 / (4 pi))
const float kShY2 = 1.0925484305920792;     // sqrt(15 / (4 pi))
const float kShY20 = 0.31539156525252005;   // sqrt(5 / (16 pi))
const float kShY22 = 0.5462742152960396;    // sqrt(15 / (16 pi))
const float kShC1 = 0.42904276540489171;    // sqrt(15 pi) / 16
const float kShC2 = 0.51166335397324424;    // sqrt(3 pi) / 6
const float kShC3 = 0.74312385577931897;    // 3 sqrt(5 pi) / 16
const float kShC4 = 0.88622692545275801;    // sqrt(pi) / 2
const float kShC5 = 0.24770795192643966;    // sqrt(5 pi) / 16

// Y_lm(d) at index l (l + 1) + m for a unit d.
void sh_basis(vec3 d, out float y[9]) {
  y[0] = kShY00;
  y[1] = kShY1 * d.y;
  y[2] = kShY1 * d.z;
  y[3] = kShY1 * d.x;
  y[4] = kShY2 * d.x * d.y;
  y[5] = kShY2 * d.y * d.z;
  y[6] = kShY20 * (3.0 * d.z * d.z - 1.0);
  y[7] = kShY2 * d.x * d.z;
  y[8] = kShY22 * (d.x * d.x - d.y * d.y);
}

// M of R&H for one channel's 9 coefficients e[base .. base + 8] (column-major, symmetric).
mat4 sh_irradiance_matrix(float e[27], int base) {
  float e00 = e[base], e1m1 = e[base + 1], e10 = e[base + 2], e11 = e[base + 3];
  float e2m2 = e[base + 4], e2m1 = e[base + 5], e20 = e[base + 6], e21 = e[base + 7],
        e22 = e[base + 8];
  return mat4(kShC1 * e22, kShC1 * e2m2, kShC1 * e21, kShC2 * e11,
              kShC1 * e2m2, -kShC1 * e22, kShC1 * e2m1, kShC2 * e1m1,
              kShC1 * e21, kShC1 * e2m1, kShC3 * e20, kShC2 * e10,
              kShC2 * e11, kShC2 * e1m1, kShC2 * e10, kShC4 * e00 - kShC5 * e20);
}

// B(n) = r^T M r, r = (n, 1) (seed eq. 10).
float sh_irradiance(mat4 m, vec3 n) {
  vec4 r = vec4(n, 1.0);
  return dot(r, m * r);
}

// Seed eq. 12 with d_eff = sqrt(d^2 + z_r^2), z_r = 1 / sigma_t' (sh::attenuation).
float sh_attenuation(float d_mm, float sigma_tr, float sigma_t_reduced) {
  if (!(sigma_t_reduced > 0.0)) return 0.0;
  float d = max(d_mm, 0.0);
  float z_r = 1.0 / sigma_t_reduced;
  float d2 = d * d + z_r * z_r;
  float d_eff = sqrt(d2);
  float s = sigma_tr * d_eff;
  return (s + 1.0) * exp(-s) / (sigma_t_reduced * d2 * d_eff);
}

// Eq. 12 integrated over a plane at distance d_eff (sh::attenuation_slab): 2 pi e^(-sigma_tr d) /
// (sigma_t' d).
float sh_attenuation_slab(float d_mm, float sigma_tr, float sigma_t_reduced) {
  if (!(sigma_t_reduced > 0.0)) return 0.0;
  float d = max(d_mm, 0.0);
  float z_r = 1.0 / sigma_t_reduced;
  float d_eff = sqrt(d * d + z_r * z_r);
  return 2.0 * 3.14159265358979 * exp(-sigma_tr * d_eff) / (sigma_t_reduced * d_eff);
}

// Face coordinate of texel i's centre on a face of w texels (sh::texel_centre_coordinate).
float sh_texel_centre(int i, int w) { return 2.0 * (float(i) + 0.5) / float(w) - 1.0; }

// The cube point of face f at (u, v): the inverse of the OpenGL face-selection table
// (sh::cube_face_point).
vec3 sh_cube_face_point(int f, float u, float v) {
  if (f == 0) return vec3(1.0, -v, -u);
  if (f == 1) return vec3(-1.0, -v, u);
  if (f == 2) return vec3(u, 1.0, v);
  if (f == 3) return vec3(u, -1.0, -v);
  if (f == 4) return vec3(u, -v, 1.0);
  return vec3(-u, -v, -1.0);
}

// Differential solid angle of a texel at (u, v) on a face of w texels (sh::texel_weight):
// (2 / W)^2 (1 + u^2 + v^2)^(-3/2).
float sh_texel_weight(float u, float v, int w) {
  float h = 2.0 / float(w);
  float q = 1.0 + u * u + v * v;
  return h * h / (q * sqrt(q));
}

// Where origin + t dir (t >= 0) leaves the box (sh::ray_box_exit).
vec3 sh_ray_box_exit(vec3 box_min, vec3 box_max, vec3 origin, vec3 dir) {
  vec3 o = min(max(origin, box_min), box_max);
  int axis = -1;
  float t_exit = 0.0;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0.0) continue;
    float t = ((dir[a] > 0.0 ? box_max[a] : box_min[a]) - o[a]) / dir[a];
    if (axis < 0 || t < t_exit) {
      axis = a;
      t_exit = t;
    }
  }
  if (axis < 0) return o;
  vec3 p = min(max(o + t_exit * dir, box_min), box_max);
  p[axis] = dir[axis] > 0.0 ? box_max[axis] : box_min[axis];
  return p;
}

// The cube-map direction of a box point with the box scaled to a cube (sh::box_lookup_direction).
vec3 sh_box_lookup_direction(vec3 box_min, vec3 box_max, vec3 p) {
  vec3 centre = 0.5 * (box_min + box_max);
  vec3 half_extent = 0.5 * (box_max - box_min);
  vec3 q;
  for (int a = 0; a < 3; ++a) q[a] = half_extent[a] > 0.0 ? (p[a] - centre[a]) / half_extent[a] : 0.0;
  return normalize(q);
}

#endif
