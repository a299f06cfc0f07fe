// lucent GLSL 1: the tabulated model (docs/DESIGN.md §4.2), twin of TabulatedModel<double>::radiance in
// materials/include/lucent/materials/tabulated.h: per channel, one row of log(pi L / (sigma_t'^2
// alpha')) over uniform nodes in ln(rho), rho = r sigma_t' (the material's (u, eta, g) already
// combined on the CPU by TabulatedProfile::rows_at: what a fixed material evaluates), as a
// texture of 3 rows; cubic Hermite with central-difference tangents inside (uniform_hermite_weights),
// linear in ln rho below the first node, linear in rho (falling only) beyond the last
// (interpolate_row). tests/render/glsl_twin_test.cpp holds it against the C++ model.
#ifndef LUCENT_BSSRDF_TABULATED_GLSL
#define LUCENT_BSSRDF_TABULATED_GLSL

#include "math.glsl"

// One channel. Member order is the layout of render/gl/gl_bssrdf.h TabulatedChannelData.
struct TabulatedChannel {
  float sigma_t;  // sigma_t', mm^-1
  float scale;    // sigma_t'^2 alpha' / (pi F_t(eta, 1)), mm^-2; 0: the channel does not scatter
  float x0;       // ln rho of node 0
  float h;        // node spacing in ln rho
  int nodes;      // J
  int row;        // row of the texture
};

float tabulated_log_value(sampler2D rows, TabulatedChannel c, float rho) {
  float lr = log(rho);
  int J = c.nodes;
  float x_last = c.x0 + float(J - 1) * c.h;
  if (lr > x_last) {
    float f1 = texelFetch(rows, ivec2(J - 1, c.row), 0).r;
    float f0 = texelFetch(rows, ivec2(J - 2, c.row), 0).r;
    float slope = min((f1 - f0) / c.h, 0.0);
    return f1 + slope * (rho / exp(x_last) - 1.0);
  }
  float pos = (lr - c.x0) / c.h;
  int i = pos > 0.0 ? min(int(pos), J - 2) : 0;
  float s = (lr - (c.x0 + float(i) * c.h)) / c.h;
  if (!(pos > 0.0)) {  // below the first node: linear from the first cell
    float f0 = texelFetch(rows, ivec2(0, c.row), 0).r;
    float f1 = texelFetch(rows, ivec2(1, c.row), 0).r;
    return (1.0 - s) * f0 + s * f1;
  }
  float s2 = s * s, s3 = s2 * s;
  float h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h10 = s3 - 2.0 * s2 + s;
  float h01 = -2.0 * s3 + 3.0 * s2, h11 = s3 - s2;
  vec4 w;
  int first;
  if (i == 0) {
    first = 0;
    w = vec4(h00 - h10 - 0.5 * h11, h01 + h10, 0.5 * h11, 0.0);
  } else if (i + 1 == J - 1) {
    first = i - 1;
    w = vec4(-0.5 * h10, h00 - h11, h01 + 0.5 * h10 + h11, 0.0);
  } else {
    first = i - 1;
    w = vec4(-0.5 * h10, h00 - 0.5 * h11, h01 + 0.5 * h10, 0.5 * h11);
  }
  float sum = 0.0;
  for (int k = 0; k < 4; ++k) {
    if (w[k] != 0.0) sum += w[k] * texelFetch(rows, ivec2(first + k, c.row), 0).r;
  }
  return sum;
}

// S_d per mm^2 per sr without the Fresnel factors: pi L(r) / (pi F_t(eta, 1)), so that with the
// outgoing F_t along the normal it is the table's radiance.
float tabulated_S_d(sampler2D rows, TabulatedChannel c, float r) {
  if (!(c.scale > 0.0)) return 0.0;
  float rho = max(r * c.sigma_t, 1e-12);
  return c.scale * exp(tabulated_log_value(rows, c, rho));
}

#endif
