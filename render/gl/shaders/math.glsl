// lucent GLSL 1: shared numerics. GLSL has no log1p or expm1; these stand in for the std:: functions
// the C++ models call (materials/include/lucent/materials/directional_dipole.h, dipole.h). Both are
// written without the "(1 + x) - 1" tricks, which need IEEE rounding that GPU compilers do not
// promise, so they stay accurate on any driver.
#ifndef LUCENT_MATH_GLSL
#define LUCENT_MATH_GLSL

const float kPi = 3.14159265358979;

// log(1 + x) for x > -1. |x| < 1/2: 2 atanh(s), s = x / (2 + x), |s| <= 1/3, by its odd series to
// s^15 (truncation below 2e-9 relative). Elsewhere 1 + x carries no cancellation.
float lucent_log1p(float x) {
  if (abs(x) >= 0.5) return log(1.0 + x);
  float s = x / (2.0 + x);
  float s2 = s * s;
  float series =
      1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0 +
      s2 * (1.0 / 11.0 + s2 * (1.0 / 13.0 + s2 * (1.0 / 15.0)))))));
  return 2.0 * s * series;
}

// exp(x) - 1. |x| < 1/2: Taylor series to x^8 (truncation below 3e-8 relative); elsewhere
// |e^x - 1| >= 0.39 and the plain difference loses nothing.
float lucent_expm1(float x) {
  if (abs(x) >= 0.5) return exp(x) - 1.0;
  return x * (1.0 + x * (1.0 / 2.0 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 +
         x * (1.0 / 720.0 + x * (1.0 / 5040.0 + x * (1.0 / 40320.0))))))));
}

#endif
