// lucent GLSL 1: the directional dipole S_d (Frisvad, Hachisuka and Kjeldsen 2014; Dal Corso 2014 §3.4.8,
// docs/DESIGN.md §4.1), twin of DirectionalDipole<float>::S_d in
// materials/include/lucent/materials/directional_dipole.h, step for step: the same modified normal,
// the same offsets from r^2, the same real-minus-virtual difference taken algebraically, the same
// guards. tests/render/glsl_twin_test.cpp holds the two together on >= 10^4 random configurations.
// Lengths in mm, coefficients in mm^-1; S_d per mm^2 per sr for unit incident flux, without the two
// Fresnel transmittances, clamped at 0.
#ifndef LUCENT_BSSRDF_DDIPOLE_GLSL
#define LUCENT_BSSRDF_DDIPOLE_GLSL

#include "math.glsl"

// One colour channel's derived coefficients, computed on the CPU in double
// (materials::derive_coefficients) and rounded once, as the float C++ model does; the Fresnel-moment
// fits lose digits in float. Member order is the std430 layout of render/gl/gl_bssrdf.h.
struct DdipoleChannel {
  float alpha_prime;    // reduced albedo; 0: the channel does not scatter and S_d = 0
  float eta;            // relative index n_sample / n_outside
  float D;              // 1 / (3 sigma_t'), mm
  float sigma_tr;       // sqrt(sigma_a / D), mm^-1
  float sigma_t;        // unreduced extinction, mm^-1 (back-lit real-source depth)
  float d_e;            // 2.131 D / sqrt(alpha'), mm
  float C_phi;          // C_phi(eta)
  float C_E;            // C_E(eta)
  float A;              // (1 - C_E) / (2 C_phi)
  float normalisation;  // 1 / (4 C_phi(1 / eta))
};

// The parts of S_d that depend on the geometry and eta only, shared by the three channels of one
// material (lucent materials have one index of refraction).
struct DdipoleGeometry {
  vec3 x;       // x_o - x_i, mm
  float r2;     // |x|^2, mm^2
  vec3 n_star;  // modified tangent-plane normal n_i*
  float x_n;    // x . n_i* (0 when n_i* is the modified normal)
  vec3 w_r;     // refracted real-source direction
  vec3 w_v;     // mirrored virtual-source direction
};

DdipoleGeometry ddipole_geometry(vec3 x_i, vec3 n_i, vec3 w_i, vec3 x_o, float eta) {
  DdipoleGeometry g;
  g.x = x_o - x_i;
  g.r2 = dot(g.x, g.x);
  float r = g.r2 > 0.0 ? sqrt(g.r2) : 0.0;
  // n_i* = (x / r) x normalize(n_i x x); n_i where that is undefined (x_o = x_i, x along n_i).
  // x . n_i* is exactly 0 by construction there and taken as 0 (its rounding would swamp the
  // virtual source's offset far from the source).
  g.n_star = n_i;
  g.x_n = dot(g.x, n_i);
  vec3 nx = cross(n_i, g.x);
  float nx2 = dot(nx, nx);
  if (g.r2 > 0.0 && nx2 > 1e-24 * g.r2) {
    g.n_star = cross(g.x / r, nx / sqrt(nx2));
    g.x_n = 0.0;
  }
  // Snell with relative index 1/eta; the radicand is clamped at 0 beyond the critical angle.
  float cos_i = dot(w_i, n_i);
  float inv_eta = 1.0 / eta;
  float radicand = max(1.0 - (1.0 - cos_i * cos_i) * inv_eta * inv_eta, 0.0);
  g.w_r = normalize(-w_i * inv_eta - n_i * (-cos_i * inv_eta + sqrt(radicand)));
  g.w_v = g.w_r - 2.0 * dot(g.w_r, g.n_star) * g.n_star;
  return g;
}

// S'(x, w_r, d_r) - S'(x_v, w_v, d_v), clamped at 0, with the difference taken term by term where
// the two sources nearly cancel (see DirectionalDipole::difference_of_sources for the algebra).
float ddipole_difference_of_sources(DdipoleChannel c, vec3 x, vec3 w_r, float d_r2, vec3 x_ov,
                                    vec3 w_v, float d_v2, float delta2, float a, float b, float x_n,
                                    vec3 n_star, vec3 n_o) {
  float sigma = c.sigma_tr;
  float D = c.D;
  float d_r = sqrt(d_r2);
  float d_v = sqrt(d_v2);
  float dd = -delta2 / (d_r + d_v);  // d_r - d_v

  float s_v = sigma * d_v;
  float u_v = 1.0 + s_v;
  float yw_v = dot(x_ov, w_v), wn_v = dot(w_v, n_o), yn_v = dot(x_ov, n_o);
  float q_v = 1.0 / d_v2;
  float H_v = 3.0 * u_v + s_v * s_v;
  float G_v = u_v + 3.0 * D * H_v * q_v * yw_v;
  float B_v = c.C_phi * (d_v2 / D + 3.0 * u_v * yw_v) - c.C_E * (3.0 * D * u_v * wn_v - G_v * yn_v);

  float s_r = sigma * d_r;
  float u_r = 1.0 + s_r;
  float q_r = 1.0 / d_r2;
  float H_r = 3.0 * u_r + s_r * s_r;

  // F = e^(-sigma (d_v - d_r)) (d_r / d_v)^3.
  float log_F = sigma * dd - 1.5 * lucent_log1p(delta2 * q_r);
  float bracket;
  if (log_F < -0.7) {
    // The virtual source is the much weaker one: the plain difference is well conditioned.
    float yw_r = dot(x, w_r), wn_r = dot(w_r, n_o), yn_r = dot(x, n_o);
    float G_r = u_r + 3.0 * D * H_r * q_r * yw_r;
    float B_r =
        c.C_phi * (d_r2 / D + 3.0 * u_r * yw_r) - c.C_E * (3.0 * D * u_r * wn_r - G_r * yn_r);
    bracket = B_r - B_v * exp(log_F);
  } else {
    float d_u = sigma * dd;                         // u_r - u_v
    float d_yw = b * x_n - a * dot(w_r, n_star);    // (y.w)_r - (y.w)_v
    float d_wn = b * dot(n_star, n_o);              // (w.n_o)_r - (w.n_o)_v
    float d_yn = a * dot(n_star, n_o);              // (y.n_o)_r - (y.n_o)_v
    float d_q = delta2 * q_r * q_v;                 // 1/d_r^2 - 1/d_v^2
    float d_H = 3.0 * d_u - sigma * sigma * delta2; // H_r - H_v
    float d_G = d_u + 3.0 * D * (H_r * q_r * d_yw + H_r * d_q * yw_v + d_H * q_v * yw_v);
    float G_r = G_v + d_G;
    float d_B = c.C_phi * (-delta2 / D + 3.0 * (u_r * d_yw + d_u * yw_v)) -
                c.C_E * (3.0 * D * (u_r * d_wn + d_u * wn_v) - (G_r * d_yn + d_G * yn_v));
    bracket = d_B - B_v * lucent_expm1(log_F);
  }
  float prefactor = c.normalisation / (4.0 * kPi * kPi) * exp(-s_r - 1.5 * log(d_r2));
  float S = prefactor * bracket;
  return S > 0.0 ? S : 0.0;
}

// One channel of S_d for a precomputed geometry (g from ddipole_geometry with c.eta).
float ddipole_channel(DdipoleChannel c, DdipoleGeometry g, vec3 n_o) {
  if (!(c.alpha_prime > 0.0)) return 0.0;  // d_e divides by sqrt(alpha')
  // Real source: through the extrapolated boundary when front-lit, one unreduced mean free path
  // below the surface when back-lit; kept as offsets from r^2.
  float mu0 = -dot(n_o, g.w_r);
  float real_offset;
  if (mu0 > 0.0) {
    vec3 across = cross(g.x, g.w_r);  // |x cross w_r|^2 = r^2 - (x.w_r)^2 without cancellation
    float across2 = dot(across, across);
    float cos_beta = across2 > 0.0 ? -sqrt(across2 / (g.r2 + c.d_e * c.d_e)) : 0.0;
    float D_mu0 = c.D * mu0;
    real_offset = D_mu0 * (D_mu0 - 2.0 * c.d_e * cos_beta);
  } else {
    float inv = 1.0 / (3.0 * c.sigma_t);
    real_offset = inv * inv;
  }
  // Virtual source x_v = x_i + a n_i*: d_v^2 = r^2 + a^2 - 2 a (x . n_i*), kept positive.
  float a = 2.0 * c.A * c.d_e;
  vec3 x_ov = g.x - a * g.n_star;
  float virtual_offset = a * a - 2.0 * a * g.x_n;
  float min_d2 = 1e-12 * c.d_e * c.d_e;
  if (g.r2 + virtual_offset < min_d2) virtual_offset = min_d2 - g.r2;
  return ddipole_difference_of_sources(c, g.x, g.w_r, g.r2 + real_offset, x_ov, g.w_v,
                                       g.r2 + virtual_offset, virtual_offset - real_offset, a,
                                       2.0 * dot(g.w_r, g.n_star), g.x_n, g.n_star, n_o);
}

// S_d(x_i, n_i, w_i, x_o, n_o) for one channel: w_i the unit direction from x_i toward the light,
// n_i and n_o outward unit normals, positions in mm.
float ddipole_S_d(DdipoleChannel c, vec3 x_i, vec3 n_i, vec3 w_i, vec3 x_o, vec3 n_o) {
  if (!(c.alpha_prime > 0.0)) return 0.0;
  return ddipole_channel(c, ddipole_geometry(x_i, n_i, w_i, x_o, c.eta), n_o);
}

// All three channels of a material; they share eta (channel 0's), so the geometry is built once.
vec3 ddipole_S_d_rgb(DdipoleChannel c[3], vec3 x_i, vec3 n_i, vec3 w_i, vec3 x_o, vec3 n_o) {
  DdipoleGeometry g = ddipole_geometry(x_i, n_i, w_i, x_o, c[0].eta);
  return vec3(ddipole_channel(c[0], g, n_o), ddipole_channel(c[1], g, n_o),
              ddipole_channel(c[2], g, n_o));
}

#endif
