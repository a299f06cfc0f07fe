// lucent GLSL 1: twin of render/core/polygon_form_factor.h: the point-to-polygon
// form factor by the contour sum (Jacob 1993 eq. 19, the angle by atan2) after clipping the polygon to
// the receiver's tangent half-space; F > 0 on the side of the winding normal. Held to the C++ by
// tests/render/glsl_twin_test.cpp.
#ifndef LUCENT_FORM_FACTOR_GLSL
#define LUCENT_FORM_FACTOR_GLSL

#include "math.glsl"

#define LUCENT_MAX_POLYGON_VERTICES 8

struct FormFactor {
  float F;             // signed form factor
  vec3 vector_;        // (1 / 2 pi) sum of the edge vectors; dot(n, vector_) = F
  float clipped_area;  // mm^2 of the polygon above the tangent plane
};

// atan2(y, x) for y >= 0 to float precision (llvmpipe's built-in atan is good to ~1e-4 only,
// which the contour sum's cancellation amplifies): reduced to |u| <= tan(pi / 8) and the Taylor
// series to u^15 (truncation < 2e-8).
float form_factor_atan2(float y, float x) {
  float ax = abs(x);
  float m = max(ax, y);
  if (!(m > 0.0)) return 0.0;
  bool swap = y > ax;
  float t = (swap ? ax : y) / m;
  float base = 0.0;
  if (t > 0.41421356) {
    t = (t - 1.0) / (t + 1.0);
    base = 0.25 * kPi;
  }
  float z = t * t;
  float series = 1.0 + z * (-1.0 / 3.0 + z * (1.0 / 5.0 + z * (-1.0 / 7.0 + z * (1.0 / 9.0 +
                 z * (-1.0 / 11.0 + z * (1.0 / 13.0 + z * (-1.0 / 15.0)))))));
  float a = base + t * series;
  if (swap) a = 0.5 * kPi - a;
  if (x < 0.0) a = kPi - a;
  return a;
}

// p: the polygon's vertices (mm), `count` of them (3..LUCENT_MAX_POLYGON_VERTICES).
FormFactor polygon_form_factor(vec3 x, vec3 n, vec3 p[LUCENT_MAX_POLYGON_VERTICES], int count) {
  FormFactor result = FormFactor(0.0, vec3(0.0), 0.0);
  vec3 c[2 * LUCENT_MAX_POLYGON_VERTICES];
  int m = 0;
  for (int i = 0; i < count; ++i) {
    vec3 a = p[i] - x;
    vec3 b = p[(i + 1) % count] - x;
    float da = dot(n, a), db = dot(n, b);
    if (da >= 0.0) c[m++] = a;
    if ((da >= 0.0) != (db >= 0.0)) c[m++] = a + (da / (da - db)) * (b - a);
  }
  if (m < 3) return result;
  vec3 area = vec3(0.0);
  for (int i = 0; i < m; ++i) {
    vec3 a = c[i];
    vec3 b = c[(i + 1) % m];
    area += cross(a - c[0], b - c[0]);  // about a vertex: distant receivers cancel in float
    vec3 e = cross(b, a);
    float len = length(e);
    if (!(len > 0.0)) continue;
    result.vector_ += (form_factor_atan2(len, dot(a, b)) / len) * e;
  }
  result.vector_ /= 2.0 * kPi;
  result.F = dot(n, result.vector_);
  result.clipped_area = 0.5 * length(area);
  return result;
}

#endif
